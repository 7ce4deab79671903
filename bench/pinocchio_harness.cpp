// Pinocchio side of bench/run.py: build a symdyn Robot (a chain or a kinematic tree on a fixed base,
// without mimic joints) as a pinocchio::Model, check it against
// symdyn.rnea's numbers, and time rnea, crba, computeGeneralizedGravity, computeCoriolisMatrix,
// aba and computeJointTorqueRegressor on the same pre-generated states as the C harness; and the
// analytical derivatives computeRNEADerivatives, computeABADerivatives and computeMinverse
// (checked against central differences of Pinocchio's own rnea and aba and against the inverse
// of crba).
//
//   pinocchio_harness MODEL.txt REPS TARGET_MS
//
// MODEL.txt (whitespace separated, written by bench/run.py):
//   n N
//   gravity gx gy gz
//   N lines: joint R|P PARENT  ax ay az  R00 R01 R02 R10 R11 R12 R20 R21 R22  px py pz
//                    mass cx cy cz  Ixx Ixy Ixz Iyy Iyz Izz  armature
//     (PARENT: the 0-based line of the parent joint, -1 for the base; parents come before their
//      children (depth-first order), so joint line i becomes Pinocchio's joint i + 1 and
//      PARENT its parent joint PARENT + 1, 0 being Pinocchio's universe; placement (R, p) of the
//      body frame in the parent body frame at q = 0; the axis in the body frame; inertia about
//      the centre of mass, body axes; armature = gear_ratio^2 J_m)
//   nstates K           then K lines: q(N) qd(N) qdd(N) tau(N)
//   ncheck C            then C lines: k  tau(N) M(N*N, row-major) G(N) V(N) qdd(N)
//     (symdyn.rnea's numbers for state k: rnea without friction, the CRBA, gravity, the
//      velocity terms, and the forward dynamics without friction for the state's tau)
//
// Output, one line each:
//   info  joints N  pinocchio VERSION  eigen X.Y.Z
//   check ALGORITHM MAX_RELATIVE_ERROR
//   time  ALGORITHM ITERATIONS_PER_REP NS_PER_CALL_REP1 NS_PER_CALL_REP2 ...
//     (repetitions interleaved across the six algorithms; bench/run.py takes the median)
//
// Compiled by bench/run.py with g++ -O3 -march=native -DNDEBUG -std=c++17 against the
// pinocchio and Eigen headers of the `pin` and `cmeel-eigen` wheels (header-only use: the
// templates are instantiated here with these flags, not taken from libpinocchio).
#include "pinocchio_model.hpp"

#include "pinocchio/algorithm/aba-derivatives.hpp"
#include "pinocchio/algorithm/aba.hpp"
#include "pinocchio/algorithm/crba.hpp"
#include "pinocchio/algorithm/regressor.hpp"
#include "pinocchio/algorithm/rnea-derivatives.hpp"
#include "pinocchio/algorithm/rnea.hpp"


// The derivatives against central differences (step 1e-6) of rnea and aba, M^-1 against crba.
static void check_derivatives(
  const Model & model, Data & data, const std::vector<VectorXd> & Q, const std::vector<VectorXd> & QD,
  const std::vector<VectorXd> & QDD, const std::vector<VectorXd> & TAU, int count)
{
  const int n = model.nv;
  const double h = 1e-6;
  double e_rd = 0, e_ad = 0, e_mi = 0;
  MatrixXd dq(n, n), dv(n, n), da(n, n), fq(n, n), fv(n, n);
  for (int k = 0; k < count; ++k)
  {
    pinocchio::computeRNEADerivatives(model, data, Q[k], QD[k], QDD[k], dq, dv, da);
    pinocchio::computeABADerivatives(model, data, Q[k], QD[k], TAU[k], fq, fv, da);
    for (int j = 0; j < n; ++j)
    {
      VectorXd e = VectorXd::Zero(n);
      e[j] = h;
      // rnea and aba return a reference into `data`: copy each result before the next call
      auto diff = [&](auto && f) -> VectorXd {
        const VectorXd plus = f(e);
        const VectorXd minus = f(VectorXd(-e));
        return (plus - minus) / (2 * h);
      };
      const VectorXd cq = diff([&](const VectorXd & d) { return pinocchio::rnea(model, data, Q[k] + d, QD[k], QDD[k]); });
      const VectorXd cv = diff([&](const VectorXd & d) { return pinocchio::rnea(model, data, Q[k], QD[k] + d, QDD[k]); });
      const VectorXd aq = diff([&](const VectorXd & d) { return pinocchio::aba(model, data, Q[k] + d, QD[k], TAU[k]); });
      const VectorXd av = diff([&](const VectorXd & d) { return pinocchio::aba(model, data, Q[k], QD[k] + d, TAU[k]); });
      e_rd = std::max({e_rd, rel_err(dq.col(j), cq), rel_err(dv.col(j), cv)});
      e_ad = std::max({e_ad, rel_err(fq.col(j), aq), rel_err(fv.col(j), av)});
    }
    const MatrixXd Minv = symmetric(pinocchio::computeMinverse(model, data, Q[k]));
    const MatrixXd M = symmetric(pinocchio::crba(model, data, Q[k]));
    e_mi = std::max(e_mi, rel_err(Minv * M, MatrixXd::Identity(n, n)));
  }
  std::printf("dcheck rnea_derivatives %.3e\n", e_rd);
  std::printf("dcheck aba_derivatives %.3e\n", e_ad);
  std::printf("dcheck minverse %.3e\n", e_mi);
}
int main(int argc, char ** argv)
{
  if (argc != 4)
    fail("usage: pinocchio_harness MODEL.txt REPS TARGET_MS");
  std::ifstream in(argv[1]);
  if (!in)
    fail(std::string("cannot read ") + argv[1]);
  const int reps = std::max(1, std::atoi(argv[2]));
  const double target_ns = 1e6 * std::atof(argv[3]);

  int n = 0;
  Model model = build_model(in, n);
  Data data(model);

  const States states = read_states(in, n);
  const int K = states.K;
  const std::vector<VectorXd> &Q = states.Q, &QD = states.QD, &QDD = states.QDD, &TAU = states.TAU;

  // --- check against symdyn.rnea
  expect(in, "ncheck");
  const int C = read<int>(in, "ncheck");
  double e_rnea = 0, e_crba = 0, e_grav = 0, e_cor = 0, e_aba = 0, e_reg = 0;
  // the inertial parameters in toDynamicParameters order: Y pi + armature qdd is rnea's tau
  VectorXd pi(10 * n);
  for (int j = 0; j < n; ++j)
    pi.segment<10>(10 * j) = model.inertias[j + 1].toDynamicParameters();
  for (int c = 0; c < C; ++c)
  {
    const int k = read<int>(in, "check state");
    if (k < 0 || k >= K)
      fail("check state out of range");
    VectorXd tau(n), G(n), V(n), qdd(n);
    MatrixXd M(n, n);
    for (int j = 0; j < n; ++j)
      tau[j] = read<double>(in, "tau");
    for (int r = 0; r < n; ++r)
      for (int j = 0; j < n; ++j)
        M(r, j) = read<double>(in, "M");
    for (int j = 0; j < n; ++j)
      G[j] = read<double>(in, "G");
    for (int j = 0; j < n; ++j)
      V[j] = read<double>(in, "V");
    for (int j = 0; j < n; ++j)
      qdd[j] = read<double>(in, "qdd");

    e_rnea = std::max(e_rnea, rel_err(pinocchio::rnea(model, data, Q[k], QD[k], QDD[k]), tau));
    MatrixXd Mp = pinocchio::crba(model, data, Q[k]);
    Mp.triangularView<Eigen::StrictlyLower>() = Mp.transpose().triangularView<Eigen::StrictlyLower>();
    e_crba = std::max(e_crba, rel_err(Mp, M));
    e_grav =
      std::max(e_grav, rel_err(pinocchio::computeGeneralizedGravity(model, data, Q[k]), G));
    const MatrixXd Cp = pinocchio::computeCoriolisMatrix(model, data, Q[k], QD[k]);
    e_cor = std::max(e_cor, rel_err(Cp * QD[k], V));
    e_aba = std::max(e_aba, rel_err(pinocchio::aba(model, data, Q[k], QD[k], TAU[k]), qdd));
    const MatrixXd Y = pinocchio::computeJointTorqueRegressor(model, data, Q[k], QD[k], QDD[k]);
    e_reg = std::max(e_reg, rel_err(VectorXd(Y * pi + model.armature.cwiseProduct(QDD[k])), tau));
  }
  std::printf(
    "info joints %d pinocchio %s eigen %d.%d.%d\n", n, PINOCCHIO_VERSION, EIGEN_WORLD_VERSION,
    EIGEN_MAJOR_VERSION, EIGEN_MINOR_VERSION);
  std::printf("check rnea %.3e\n", e_rnea);
  std::printf("check crba %.3e\n", e_crba);
  std::printf("check gravity %.3e\n", e_grav);
  std::printf("check coriolis_matrix %.3e\n", e_cor);
  std::printf("check aba %.3e\n", e_aba);
  std::printf("check regressor %.3e\n", e_reg);
  check_derivatives(model, data, Q, QD, QDD, TAU, C);
  std::fflush(stdout);

  // --- timing: same states and protocol as the C harness of bench/run.py
  const int last = n - 1;
  const char * labels[] = {"rnea",     "crba",           "gravity",         "coriolis_matrix", "aba",
                           "regressor", "rnea_derivatives", "aba_derivatives", "minverse"};
  const int NB = 9;
  MatrixXd dq(n, n), dv(n, n), da(n, n);
  auto run_bench = [&](int b, long it) -> double {
    switch (b)
    {
    case 0:
      return loop(it, K, [&](int k) { return pinocchio::rnea(model, data, Q[k], QD[k], QDD[k])[k % n]; });
    case 1:  // upper triangle only, as pinocchio::crba leaves it
      return loop(it, K, [&](int k) { return pinocchio::crba(model, data, Q[k])(0, k % n); });
    case 2:
      return loop(
        it, K, [&](int k) { return pinocchio::computeGeneralizedGravity(model, data, Q[k])[k % n]; });
    case 3:
      return loop(it, K, [&](int k) {
        return pinocchio::computeCoriolisMatrix(model, data, Q[k], QD[k])(k % n, last);
      });
    case 4:
      return loop(it, K, [&](int k) { return pinocchio::aba(model, data, Q[k], QD[k], TAU[k])[k % n]; });
    case 5:
      return loop(it, K, [&](int k) {
        return pinocchio::computeJointTorqueRegressor(model, data, Q[k], QD[k], QDD[k])(k % n, 10 * n - 1);
      });
    case 6:  // dtau/dq, dtau/dqd (and dtau/dqdd = M, upper triangle)
      return loop(it, K, [&](int k) {
        pinocchio::computeRNEADerivatives(model, data, Q[k], QD[k], QDD[k], dq, dv, da);
        return dq(k % n, last) + dv(k % n, 0);
      });
    case 7:  // dqdd/dq, dqdd/dqd and dqdd/dtau = M^-1 (upper triangle)
      return loop(it, K, [&](int k) {
        pinocchio::computeABADerivatives(model, data, Q[k], QD[k], TAU[k], dq, dv, da);
        return dq(k % n, last) + dv(k % n, 0);
      });
    case 8:  // upper triangle, as Pinocchio leaves it
      return loop(it, K, [&](int k) { return pinocchio::computeMinverse(model, data, Q[k])(0, k % n); });
    }
    return -1.0;
  };
  time_benchmarks(labels, NB, run_bench, reps, target_ns);
  return 0;
}
