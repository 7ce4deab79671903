/* iLQR tracking for the Franka Panda with symdyn's generated derivatives (docs/tutorials/ilqr.md).
 *
 * The plant is xd = f(x, tau), x = (q, qd), from panda_forward_dynamics; one step of h is
 * x+ = x + h f(x, tau) (explicit Euler), so its Jacobians are Fx = I + h A and Fu = h B with
 * A, B from panda_linearize. The reference is a smooth joint-space motion q_ref(t) with
 * feed-forward torques tau_ref = panda_inverse_dynamics(q_ref, qd_ref, qdd_ref); the arm starts
 * 0.1 rad away from it on every joint. iLQR (Li and Todorov 2004) minimises
 *
 *     J = sum_k 1/2 |x_k - x_ref,k|^2_Q + 1/2 |tau_k - tau_ref,k|^2_R + 1/2 |x_N - x_ref,N|^2_Qf
 *
 * with a backward Riccati pass on the linearisation and a forward rollout with a line search,
 * until the cost decreases by less than a relative 1e-9. Prints one line per iteration and a
 * summary line:
 *
 *     iter K cost J alpha A
 *     converged ITERATIONS cost J final_error E max_error_last_half F
 *
 * (E: max |q - q_ref| at the end of the horizon, F: the largest over its second half, rad).
 *
 *     cc -std=c99 -O2 -I generated/panda panda_ilqr.c generated/panda/panda_dynamics.c -lm
 */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "panda_dynamics.h"

#define NQ panda_NDOF
#define NX (2 * NQ)
#define STEPS 100     /* horizon: STEPS steps of H seconds */
#define H 0.01
#define MAX_ITER 60

static double xs[STEPS + 1][NX], us[STEPS][NQ];  /* the current trajectory */
static double xr[STEPS + 1][NX], ur[STEPS][NQ];  /* the reference */
static double kff[STEPS][NQ], Kfb[STEPS][NQ * NX];
static double xn[STEPS + 1][NX], un[STEPS][NQ];  /* the candidate of the line search */

static const double QW = 100.0, QDW = 1.0, RW = 1e-3, FINAL = 10.0;

static double weight(int i) { return i < NQ ? QW : QDW; }

static void reference(double t, double *q, double *qd, double *qdd)
{
    for (int i = 0; i < NQ; ++i) {
        const double a = 0.3 + 0.05 * i, w = 2.0 + 0.3 * i, c = 0.2 * (i % 3) - 0.2;
        q[i] = c + a * sin(w * t);
        qd[i] = a * w * cos(w * t);
        qdd[i] = -a * w * w * sin(w * t);
    }
}

static void step(const double *x, const double *u, double *next)
{
    double qdd[NQ];
    panda_forward_dynamics(x, x + NQ, u, NULL, qdd);
    for (int i = 0; i < NQ; ++i) {
        next[i] = x[i] + H * x[NQ + i];
        next[NQ + i] = x[NQ + i] + H * qdd[i];
    }
}

static double cost(double (*x)[NX], double (*u)[NQ])
{
    double J = 0.0;
    for (int k = 0; k <= STEPS; ++k) {
        const double s = k == STEPS ? FINAL : 1.0;
        for (int i = 0; i < NX; ++i) J += 0.5 * s * weight(i) * pow(x[k][i] - xr[k][i], 2);
        if (k < STEPS)
            for (int i = 0; i < NQ; ++i) J += 0.5 * RW * pow(u[k][i] - ur[k][i], 2);
    }
    return J;
}

/* Cholesky factorisation of the NQ x NQ matrix A in place (lower triangle); 0 if not positive definite */
static int cholesky(double *A)
{
    for (int j = 0; j < NQ; ++j) {
        double d = A[j * NQ + j];
        for (int k = 0; k < j; ++k) d -= A[j * NQ + k] * A[j * NQ + k];
        if (d <= 0.0) return 0;
        A[j * NQ + j] = sqrt(d);
        for (int i = j + 1; i < NQ; ++i) {
            double s = A[i * NQ + j];
            for (int k = 0; k < j; ++k) s -= A[i * NQ + k] * A[j * NQ + k];
            A[i * NQ + j] = s / A[j * NQ + j];
        }
    }
    return 1;
}

/* b := A^-1 b for the factor L of cholesky (one right-hand side) */
static void chol_solve(const double *L, double *b)
{
    for (int i = 0; i < NQ; ++i) {
        for (int k = 0; k < i; ++k) b[i] -= L[i * NQ + k] * b[k];
        b[i] /= L[i * NQ + i];
    }
    for (int i = NQ - 1; i >= 0; --i) {
        for (int k = i + 1; k < NQ; ++k) b[i] -= L[k * NQ + i] * b[k];
        b[i] /= L[i * NQ + i];
    }
}

/* The backward pass: feedback gains Kfb and feed-forward steps kff; 0 if Quu was not positive definite */
static int backward(double mu)
{
    static double Vx[NX], Vxx[NX * NX], A[NX * NX], B[NX * NQ], Fx[NX * NX], Fu[NX * NQ];
    static double VF[NX * NX], VU[NX * NQ], Qx[NX], Qu[NQ], Qxx[NX * NX], Quu[NQ * NQ], Qux[NQ * NX];
    for (int i = 0; i < NX; ++i) {
        Vx[i] = FINAL * weight(i) * (xs[STEPS][i] - xr[STEPS][i]);
        for (int j = 0; j < NX; ++j) Vxx[i * NX + j] = i == j ? FINAL * weight(i) : 0.0;
    }
    for (int k = STEPS - 1; k >= 0; --k) {
        panda_linearize(xs[k], xs[k] + NQ, us[k], NULL, A, B);
        for (int i = 0; i < NX * NX; ++i) Fx[i] = H * A[i] + (i % (NX + 1) == 0 ? 1.0 : 0.0);
        for (int i = 0; i < NX * NQ; ++i) Fu[i] = H * B[i];
        /* VF = Vxx Fx, VU = Vxx Fu */
        for (int i = 0; i < NX; ++i) {
            for (int j = 0; j < NX; ++j) {
                double s = 0.0;
                for (int m = 0; m < NX; ++m) s += Vxx[i * NX + m] * Fx[m * NX + j];
                VF[i * NX + j] = s;
            }
            for (int j = 0; j < NQ; ++j) {
                double s = 0.0;
                for (int m = 0; m < NX; ++m) s += Vxx[i * NX + m] * Fu[m * NQ + j];
                VU[i * NQ + j] = s;
            }
        }
        for (int i = 0; i < NX; ++i) {
            double s = weight(i) * (xs[k][i] - xr[k][i]);
            for (int m = 0; m < NX; ++m) s += Fx[m * NX + i] * Vx[m];
            Qx[i] = s;
            for (int j = 0; j < NX; ++j) {
                double t = i == j ? weight(i) : 0.0;
                for (int m = 0; m < NX; ++m) t += Fx[m * NX + i] * VF[m * NX + j];
                Qxx[i * NX + j] = t;
            }
        }
        for (int i = 0; i < NQ; ++i) {
            double s = RW * (us[k][i] - ur[k][i]);
            for (int m = 0; m < NX; ++m) s += Fu[m * NQ + i] * Vx[m];
            Qu[i] = s;
            for (int j = 0; j < NQ; ++j) {
                double t = i == j ? RW + mu : 0.0;
                for (int m = 0; m < NX; ++m) t += Fu[m * NQ + i] * VU[m * NQ + j];
                Quu[i * NQ + j] = t;
            }
            for (int j = 0; j < NX; ++j) {
                double t = 0.0;
                for (int m = 0; m < NX; ++m) t += Fu[m * NQ + i] * VF[m * NX + j];
                Qux[i * NX + j] = t;
            }
        }
        if (!cholesky(Quu)) return 0;
        /* k = -Quu^-1 Qu, K = -Quu^-1 Qux (column by column) */
        for (int i = 0; i < NQ; ++i) kff[k][i] = -Qu[i];
        chol_solve(Quu, kff[k]);
        for (int j = 0; j < NX; ++j) {
            double col[NQ];
            for (int i = 0; i < NQ; ++i) col[i] = -Qux[i * NX + j];
            chol_solve(Quu, col);
            for (int i = 0; i < NQ; ++i) Kfb[k][i * NX + j] = col[i];
        }
        /* Vx = Qx + Qux^T k, Vxx = Qxx + Qux^T K (with K = -Quu^-1 Qux), symmetrised */
        for (int i = 0; i < NX; ++i) {
            double s = Qx[i];
            for (int m = 0; m < NQ; ++m) s += Qux[m * NX + i] * kff[k][m];
            Vx[i] = s;
            for (int j = 0; j < NX; ++j) {
                double t = Qxx[i * NX + j];
                for (int m = 0; m < NQ; ++m) t += Qux[m * NX + i] * Kfb[k][m * NX + j];
                Vxx[i * NX + j] = t;
            }
        }
        for (int i = 0; i < NX; ++i)
            for (int j = 0; j < i; ++j)
                Vxx[i * NX + j] = Vxx[j * NX + i] = 0.5 * (Vxx[i * NX + j] + Vxx[j * NX + i]);
    }
    return 1;
}

/* Roll out u = us + alpha kff + Kfb (x - xs) from the start; the candidate's cost */
static double forward(double alpha)
{
    memcpy(xn[0], xs[0], sizeof xn[0]);
    for (int k = 0; k < STEPS; ++k) {
        for (int i = 0; i < NQ; ++i) {
            double u = us[k][i] + alpha * kff[k][i];
            for (int j = 0; j < NX; ++j) u += Kfb[k][i * NX + j] * (xn[k][j] - xs[k][j]);
            un[k][i] = u;
        }
        step(xn[k], un[k], xn[k + 1]);
    }
    return cost(xn, un);
}

int main(void)
{
    double q[NQ], qd[NQ], qdd[NQ];
    for (int k = 0; k <= STEPS; ++k) {
        reference(k * H, q, qd, qdd);
        memcpy(xr[k], q, sizeof q);
        memcpy(xr[k] + NQ, qd, sizeof qd);
        if (k < STEPS) panda_inverse_dynamics(q, qd, qdd, NULL, ur[k]);
    }
    for (int i = 0; i < NX; ++i) xs[0][i] = xr[0][i] + (i < NQ ? 0.1 : 0.0);
    for (int k = 0; k < STEPS; ++k) {  /* start from the feed-forward torques alone */
        memcpy(us[k], ur[k], sizeof us[k]);
        step(xs[k], us[k], xs[k + 1]);
    }
    double J = cost(xs, us), mu = 1e-6;
    printf("iter 0 cost %.9e alpha 0\n", J);
    int it, converged = 0;
    for (it = 1; it <= MAX_ITER && !converged; ++it) {
        while (!backward(mu)) mu *= 10.0;
        double alpha = 1.0, Jn = forward(alpha);
        while (!(Jn < J) && alpha > 1e-4) Jn = forward(alpha *= 0.5);
        if (!(Jn < J)) {  /* no descent: more regularisation */
            mu *= 10.0;
            printf("iter %d cost %.9e alpha 0\n", it, J);
            converged = mu > 1e6;
            continue;
        }
        converged = (J - Jn) < 1e-9 * J;
        memcpy(xs, xn, sizeof xs);
        memcpy(us, un, sizeof us);
        J = Jn;
        mu = mu > 1e-6 ? mu / 10.0 : 1e-6;
        printf("iter %d cost %.9e alpha %g\n", it, J, alpha);
    }
    double final_error = 0.0, late = 0.0;
    for (int k = STEPS / 2; k <= STEPS; ++k)
        for (int i = 0; i < NQ; ++i) {
            const double e = fabs(xs[k][i] - xr[k][i]);
            if (e > late) late = e;
            if (k == STEPS && e > final_error) final_error = e;
        }
    printf("%s %d cost %.9e final_error %.3e max_error_last_half %.3e\n", converged ? "converged" : "stopped",
           it - 1, J, final_error, late);
    return converged ? 0 : 1;
}
