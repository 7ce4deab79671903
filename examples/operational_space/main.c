/*
 * Operational-space impedance control of the Panda's hand with symdyn's generated C
 * (docs/tutorials/operational-space.md).
 *
 * The task is the pose of the frame panda_hand: its origin follows a circle of radius R_CIRCLE
 * in the horizontal plane, once every PERIOD seconds, and its orientation stays the initial one.
 * With x the task coordinates, J the world-aligned Jacobian (rows v_x v_y v_z w_x w_y w_z),
 * Lambda = (J M^-1 J^T)^-1 and mu + p = Lambda (J M^-1 (V + G + F) - Jdot qd), the law is
 *
 *     tau = J^T (Lambda a_task + mu_p) + (I - J^T Jbar^T) tau_0,   Jbar = M^-1 J^T Lambda,
 *     a_task = xdd_d + Kd e_dot + Kp e,
 *     tau_0  = M a_0 + V + G + F,   a_0 = Kp_n (q_0 - q) - Kd_n qd   (the posture, in the null space),
 *
 * from the generated panda_panda_hand_jacobian, _jacobian_dot_qd is inside mu + p, and
 * panda_panda_hand_operational_space_inertia, _operational_space_bias, panda_mass_matrix and
 * panda_inverse_dynamics. With an exact model the hand's acceleration is exactly a_task, so the
 * position error obeys e'' + Kd e' + Kp e = 0, and the joints' V + G + F is compensated once
 * (the task part by mu + p, the rest by the null-space part of tau_0).
 * The plant is the same arm, integrated with the generated panda_forward_dynamics (classical RK4,
 * step H), the law evaluated at every stage.
 *
 * Build (after `symdyn generate examples/operational_space/panda_hand.yaml --target c
 *        --functions dynamics kinematics operational_space --frames panda_hand --out build/osc`):
 *
 *     gcc -std=c99 -Wall -Wextra -Wpedantic -Werror -O2 -I build/osc -o build/osc/controller \
 *         examples/operational_space/main.c build/osc/panda_dynamics.c -lm
 *
 * Run: `build/osc/controller` prints CSV rows every 10 ms (time, hand position, reference,
 * orientation error, joint positions) and a summary; `build/osc/controller --no-posture` runs
 * the same law with tau_0 = V + G + F (a_0 = 0): no posture term.
 * C99, no allocation.
 */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "panda_dynamics.h"

#define N panda_NDOF
#define T6 6 /* the task: x, y, z, rx, ry, rz */

static const double PI = 3.14159265358979323846;
static const double KP = 400.0;   /* task stiffness: omega^2 with omega = 20 rad/s */
static const double KD = 40.0;    /* 2 omega: critically damped */
static const double KP_N = 25.0;  /* posture stiffness (null space) */
static const double KD_N = 10.0;  /* posture damping */
static const double R_CIRCLE = 0.05; /* m */
static const double PERIOD = 2.0;    /* s */
static const double H = 1e-3;        /* integration step (s) */
static const double T_END = 3.0;
/* The posture q_0 (rad): the arm's "ready" pose, the elbow up and out. The arm starts there. */
static const double PUSH = 0.5; /* rad/s: the start's self-motion, joint 1's rate projected */
static const double Q0[N] = {0.0, -PI / 4, 0.0, -3 * PI / 4, 0.0, PI / 2, PI / 4};

static int use_posture = 1;
static double P0[3];    /* the hand's initial position: the circle starts there */
static double R0[3][3]; /* the hand's initial orientation: held */

/* The reference position p_d(t) = P0 + R (cos wt - 1, sin wt, 0) and its first two derivatives. */
static void reference(double t, double p[3], double pd[3], double pdd[3])
{
    const double w = 2.0 * PI / PERIOD, c = cos(w * t), s = sin(w * t);
    p[0] = P0[0] + R_CIRCLE * (c - 1.0);
    p[1] = P0[1] + R_CIRCLE * s;
    p[2] = P0[2];
    pd[0] = -R_CIRCLE * w * s;
    pd[1] = R_CIRCLE * w * c;
    pd[2] = 0.0;
    pdd[0] = -R_CIRCLE * w * w * c;
    pdd[1] = -R_CIRCLE * w * w * s;
    pdd[2] = 0.0;
}

/* The orientation error e_o = 1/2 sum_i r_i x r_d,i (r_i the columns of R, r_d,i those of R0):
 * sin(angle) times the axis turning R into R0, in world axes. */
static void orientation_error(const double T[16], double eo[3])
{
    int i;
    eo[0] = eo[1] = eo[2] = 0.0;
    for (i = 0; i < 3; ++i) {
        const double r[3] = {T[0 * 4 + i], T[1 * 4 + i], T[2 * 4 + i]};
        const double d[3] = {R0[0][i], R0[1][i], R0[2][i]};
        eo[0] += 0.5 * (r[1] * d[2] - r[2] * d[1]);
        eo[1] += 0.5 * (r[2] * d[0] - r[0] * d[2]);
        eo[2] += 0.5 * (r[0] * d[1] - r[1] * d[0]);
    }
}

/* y = M^-1 b by Cholesky factorisation of the symmetric positive definite M (row-major). */
static void solve_spd(const double M[N * N], const double b[N], double y[N])
{
    double L[N * N];
    int i, j, k;
    memset(L, 0, sizeof L);
    for (j = 0; j < N; ++j) {
        double d = M[j * N + j];
        for (k = 0; k < j; ++k) d -= L[j * N + k] * L[j * N + k];
        L[j * N + j] = sqrt(d);
        for (i = j + 1; i < N; ++i) {
            double s = M[i * N + j];
            for (k = 0; k < j; ++k) s -= L[i * N + k] * L[j * N + k];
            L[i * N + j] = s / L[j * N + j];
        }
    }
    for (i = 0; i < N; ++i) { /* L z = b */
        double s = b[i];
        for (k = 0; k < i; ++k) s -= L[i * N + k] * y[k];
        y[i] = s / L[i * N + i];
    }
    for (i = N - 1; i >= 0; --i) { /* L^T y = z */
        double s = y[i];
        for (k = i + 1; k < N; ++k) s -= L[k * N + i] * y[k];
        y[i] = s / L[i * N + i];
    }
}

/* A self-motion qd = (I - Jbar J) w with w = (rate, 0, ..., 0): the hand stays at rest (J qd = 0)
 * while the elbow swings, as after a push on the elbow. Jbar J w = M^-1 J^T Lambda J w. */
static void self_motion(const double q[N], double rate, double qd[N])
{
    double J[T6 * N], Lambda[T6 * T6], M[N * N], Lv[T6], y[N];
    int i, j;
    panda_panda_hand_jacobian(q, NULL, J);
    panda_panda_hand_operational_space_inertia(q, NULL, Lambda);
    panda_mass_matrix(q, NULL, M);
    for (i = 0; i < T6; ++i) { /* Lambda J w, J w = rate times J's first column */
        Lv[i] = 0.0;
        for (j = 0; j < T6; ++j) Lv[i] += Lambda[i * T6 + j] * J[j * N] * rate;
    }
    for (j = 0; j < N; ++j) { /* J^T Lambda J w */
        qd[j] = 0.0;
        for (i = 0; i < T6; ++i) qd[j] += J[i * N + j] * Lv[i];
    }
    solve_spd(M, qd, y);
    for (j = 0; j < N; ++j) qd[j] = (j == 0 ? rate : 0.0) - y[j];
}

/* The control law. The robot file has no free parameters, so p is NULL. */
static void control(double t, const double q[N], const double qd[N], double tau[N])
{
    double T[16], J[T6 * N], Lambda[T6 * T6], mu_p[T6], M[N * N];
    double v[T6], a_task[T6], f[T6], eo[3], p[3], pd[3], pdd[3];
    double a0[N], tau0[N], y[N], Jy[T6], g[T6];
    int i, j;
    panda_panda_hand_pose(q, NULL, T);
    panda_panda_hand_jacobian(q, NULL, J);
    panda_panda_hand_operational_space_inertia(q, NULL, Lambda);
    panda_panda_hand_operational_space_bias(q, qd, NULL, mu_p);
    panda_mass_matrix(q, NULL, M);

    for (i = 0; i < T6; ++i) { /* the hand's twist v = J qd (row-major: J[i*N + j]) */
        v[i] = 0.0;
        for (j = 0; j < N; ++j) v[i] += J[i * N + j] * qd[j];
    }
    reference(t, p, pd, pdd);
    orientation_error(T, eo);
    for (i = 0; i < 3; ++i) {
        a_task[i] = pdd[i] + KD * (pd[i] - v[i]) + KP * (p[i] - T[i * 4 + 3]);
        a_task[3 + i] = KD * (0.0 - v[3 + i]) + KP * eo[i];
    }
    for (i = 0; i < T6; ++i) { /* f = Lambda a_task + mu_p: the task force */
        f[i] = mu_p[i];
        for (j = 0; j < T6; ++j) f[i] += Lambda[i * T6 + j] * a_task[j];
    }

    for (i = 0; i < N; ++i) { /* tau_0 = M a_0 + V + G + F: one call of the inverse dynamics */
        a0[i] = use_posture ? KP_N * (Q0[i] - q[i]) - KD_N * qd[i] : 0.0;
    }
    panda_inverse_dynamics(q, qd, a0, NULL, tau0);

    /* (I - J^T Jbar^T) tau_0 = tau_0 - J^T Lambda J M^-1 tau_0 */
    solve_spd(M, tau0, y);
    for (i = 0; i < T6; ++i) {
        Jy[i] = 0.0;
        for (j = 0; j < N; ++j) Jy[i] += J[i * N + j] * y[j];
    }
    for (i = 0; i < T6; ++i) {
        g[i] = 0.0;
        for (j = 0; j < T6; ++j) g[i] += Lambda[i * T6 + j] * Jy[j];
    }
    for (j = 0; j < N; ++j) { /* tau = J^T (f - g) + tau_0 */
        tau[j] = tau0[j];
        for (i = 0; i < T6; ++i) tau[j] += J[i * N + j] * (f[i] - g[i]);
    }
}

/* The closed loop as a first-order system: x = (q, qd), dx/dt = (qd, forward_dynamics(q, qd, tau)). */
static void closed_loop(double t, const double x[2 * N], double dx[2 * N])
{
    double tau[N];
    int i;
    control(t, x, x + N, tau);
    for (i = 0; i < N; ++i) dx[i] = x[N + i];
    panda_forward_dynamics(x, x + N, tau, NULL, dx + N);
}

/* One classical Runge-Kutta step of length h. */
static void rk4_step(double t, double h, double x[2 * N])
{
    double k1[2 * N], k2[2 * N], k3[2 * N], k4[2 * N], y[2 * N];
    int i;
    closed_loop(t, x, k1);
    for (i = 0; i < 2 * N; ++i) y[i] = x[i] + 0.5 * h * k1[i];
    closed_loop(t + 0.5 * h, y, k2);
    for (i = 0; i < 2 * N; ++i) y[i] = x[i] + 0.5 * h * k2[i];
    closed_loop(t + 0.5 * h, y, k3);
    for (i = 0; i < 2 * N; ++i) y[i] = x[i] + h * k3[i];
    closed_loop(t + h, y, k4);
    for (i = 0; i < 2 * N; ++i) x[i] += h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]);
}

/* Prints a CSV row; returns the position error |p_d - p| (m) and sets *eo_norm to |e_o|. */
static double report(double t, const double x[2 * N], double *eo_norm)
{
    double T[16], p[3], pd[3], pdd[3], eo[3], e2 = 0.0;
    int i;
    panda_panda_hand_pose(x, NULL, T);
    reference(t, p, pd, pdd);
    orientation_error(T, eo);
    printf("%.3f", t);
    for (i = 0; i < 3; ++i) printf(",%.12e", T[i * 4 + 3]);
    for (i = 0; i < 3; ++i) printf(",%.12e", p[i]);
    *eo_norm = sqrt(eo[0] * eo[0] + eo[1] * eo[1] + eo[2] * eo[2]);
    printf(",%.6e", *eo_norm);
    for (i = 0; i < N; ++i) printf(",%.12e", x[i]);
    printf("\n");
    for (i = 0; i < 3; ++i) e2 += (p[i] - T[i * 4 + 3]) * (p[i] - T[i * 4 + 3]);
    return sqrt(e2);
}

int main(int argc, char **argv)
{
    double x[2 * N], T[16], worst_p = 0.0, worst_o = 0.0, worst_q = 0.0;
    const long steps = lround(T_END / H);
    long k;
    int i, j;

    if (argc > 2 || (argc == 2 && strcmp(argv[1], "--no-posture") != 0)) {
        fprintf(stderr, "usage: %s [--no-posture]\n", argv[0]);
        return 2;
    }
    use_posture = argc == 1;
    for (i = 0; i < N; ++i) x[i] = Q0[i];
    self_motion(x, PUSH, x + N);
    panda_panda_hand_pose(x, NULL, T);
    for (i = 0; i < 3; ++i) {
        P0[i] = T[i * 4 + 3];
        for (j = 0; j < 3; ++j) R0[i][j] = T[i * 4 + j];
    }
    printf("t,x,y,z,x_d,y_d,z_d,e_o,q1,q2,q3,q4,q5,q6,q7\n");
    {
        double eo;
        report(0.0, x, &eo);
    }
    for (k = 1; k <= steps; ++k) {
        const double t = k * H;
        rk4_step(t - H, H, x);
        if (k % 10 == 0) {
            double eo, ep = report(t, x, &eo), dq = 0.0;
            if (t > T_END - 1.0 - 1e-9) { /* the last second */
                worst_p = fmax(worst_p, ep);
                worst_o = fmax(worst_o, eo);
            }
            for (i = 0; i < N; ++i) dq += (x[i] - Q0[i]) * (x[i] - Q0[i]);
            worst_q = fmax(worst_q, sqrt(dq));
        }
    }
    printf("# max position error over the last second: %.3e m\n", worst_p);
    printf("# max orientation error over the last second: %.3e rad\n", worst_o);
    printf("# max |q - q_0| over the run: %.3e rad\n", worst_q);
    return 0;
}
