/*
 * Computed-torque control of Roger's arm with symdyn's generated C (docs/tutorials/embedded-c.md).
 *
 * The controller (R. Grupen, "Dynamics" (2015), slide 20) commands
 *
 *     tau = M(q) (qdd_ref + Kp e + Kd ed) + V(q, qd) + G(q) + F(qd),   e = q_ref - q, ed = qd_ref - qd,
 *
 * from the generated roger_arm_values_mass_matrix, _coriolis, _gravity and _friction. The plant is
 * the same arm, integrated with the generated roger_arm_values_forward_dynamics (classical RK4,
 * step H). With an exact model the error obeys e'' + Kd e' + Kp e = 0: with Kp = omega^2 and
 * Kd = 2 omega, e(0) = E0 and ed(0) = 0 it is e(t) = E0 (1 + omega t) exp(-omega t).
 *
 * Build (after `symdyn generate examples/roger_arm_values.yaml --target c --out build/embedded`):
 *
 *     gcc -std=c99 -Wall -Wextra -Wpedantic -Werror -O2 -I build/embedded -o build/embedded/controller \
 *         examples/embedded_control/main.c build/embedded/roger_arm_values_dynamics.c -lm
 *
 * C99, no allocation: every array has the size of the header's macro roger_arm_values_NDOF.
 */
#include <math.h>
#include <stdio.h>

#include "roger_arm_values_dynamics.h"

#define N roger_arm_values_NDOF

static const double KP = 100.0; /* omega^2 with omega = 10 rad/s */
static const double KD = 20.0;  /* 2 omega: critically damped */
static const double H = 1e-3;   /* integration step (s) */
static const double T_END = 3.0;
static const double E0[N] = {0.1, -0.1}; /* initial position error (rad) */

/* The reference q_ref(t) = (0.5 sin t, 0.3 cos 2t) and its first two derivatives. */
static void reference(double t, double q[N], double qd[N], double qdd[N])
{
    q[0] = 0.5 * sin(t);
    qd[0] = 0.5 * cos(t);
    qdd[0] = -0.5 * sin(t);
    q[1] = 0.3 * cos(2.0 * t);
    qd[1] = -0.6 * sin(2.0 * t);
    qdd[1] = -1.2 * cos(2.0 * t);
}

/* The commanded acceleration a = qdd_ref + Kp e + Kd ed at time t and state (q, qd). */
static void commanded_acceleration(double t, const double q[N], const double qd[N], double a[N])
{
    double r[N], rd[N], rdd[N];
    int i;
    reference(t, r, rd, rdd);
    for (i = 0; i < N; ++i) {
        a[i] = rdd[i] + KP * (r[i] - q[i]) + KD * (rd[i] - qd[i]);
    }
}

/* The control law: tau = M a + V + G + F. The robot has no free parameters, so p is NULL. */
static void control(double t, const double q[N], const double qd[N], double tau[N])
{
    double M[N * N], V[N], G[N], F[N], a[N];
    int i, j;
    commanded_acceleration(t, q, qd, a);
    roger_arm_values_mass_matrix(q, NULL, M);
    roger_arm_values_coriolis(q, qd, NULL, V);
    roger_arm_values_gravity(q, NULL, G);
    roger_arm_values_friction(qd, NULL, F);
    for (i = 0; i < N; ++i) {
        tau[i] = V[i] + G[i] + F[i];
        for (j = 0; j < N; ++j) {
            tau[i] += M[i * N + j] * a[j]; /* row-major: M[i*NDOF + j] is row i, column j */
        }
    }
}

/* The closed loop as a first-order system: x = (q, qd), dx/dt = (qd, forward_dynamics(q, qd, tau)). */
static void closed_loop(double t, const double x[2 * N], double dx[2 * N])
{
    double tau[N];
    int i;
    control(t, x, x + N, tau);
    for (i = 0; i < N; ++i) {
        dx[i] = x[N + i];
    }
    roger_arm_values_forward_dynamics(x, x + N, tau, NULL, dx + N);
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

/* The largest |inverse_dynamics(q, qd, a) - (M a + V + G + F)|: the two routes to tau agree. */
static double routes_differ(double t, const double q[N], const double qd[N])
{
    double a[N], tau_id[N], tau_ct[N], worst = 0.0;
    int i;
    commanded_acceleration(t, q, qd, a);
    roger_arm_values_inverse_dynamics(q, qd, a, NULL, tau_id);
    control(t, q, qd, tau_ct);
    for (i = 0; i < N; ++i) {
        worst = fmax(worst, fabs(tau_id[i] - tau_ct[i]));
    }
    return worst;
}

static void report(double t, const double x[2 * N])
{
    double r[N], rd[N], rdd[N];
    reference(t, r, rd, rdd);
    printf("t = %.1f s: error %.6e %.6e rad\n", t, r[0] - x[0], r[1] - x[1]);
}

int main(void)
{
    double x[2 * N], r[N], rd[N], rdd[N], worst = 0.0;
    const long steps = lround(T_END / H);
    long k;
    int i;

    reference(0.0, r, rd, rdd); /* start off the reference by E0, at its velocity */
    for (i = 0; i < N; ++i) {
        x[i] = r[i] - E0[i];
        x[N + i] = rd[i];
    }
    printf("roger_arm_values: computed-torque control, Kp = %g, Kd = %g, RK4 step %g s\n", KP, KD, H);
    report(0.0, x);
    for (k = 1; k <= steps; ++k) {
        const double t = k * H;
        rk4_step(t - H, H, x);
        worst = fmax(worst, routes_differ(t, x, x + N));
        if (k == 200 || k == 1000 || k == steps) {
            report(t, x);
        }
    }
    printf("inverse_dynamics agrees with M a + V + G + F to %.1e N m\n", worst);
    return 0;
}
