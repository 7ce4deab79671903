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
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <fstream>
#include <iostream>
#include <string>
#include <vector>

#if __has_include("pinocchio/multibody.hpp")  // pinocchio >= 4
  #include "pinocchio/multibody.hpp"
#else
  #include "pinocchio/multibody/data.hpp"
  #include "pinocchio/multibody/model.hpp"
#endif
#include "pinocchio/algorithm/aba-derivatives.hpp"
#include "pinocchio/algorithm/aba.hpp"
#include "pinocchio/algorithm/crba.hpp"
#include "pinocchio/algorithm/regressor.hpp"
#include "pinocchio/algorithm/rnea-derivatives.hpp"
#include "pinocchio/algorithm/rnea.hpp"

using pinocchio::Data;
using pinocchio::Model;
using Eigen::MatrixXd;
using Eigen::VectorXd;

static volatile double sink;

static double now_ns()
{
  timespec t;
  clock_gettime(CLOCK_MONOTONIC, &t);
  return 1e9 * double(t.tv_sec) + double(t.tv_nsec);
}

static void fail(const std::string & what)
{
  std::cerr << "pinocchio_harness: " << what << std::endl;
  std::exit(2);
}

template<typename T>
static T read(std::istream & in, const char * what)
{
  T x;
  if (!(in >> x))
    fail(std::string("bad or missing ") + what);
  return x;
}

static void expect(std::istream & in, const std::string & word)
{
  if (read<std::string>(in, word.c_str()) != word)
    fail("expected '" + word + "'");
}

static bool is_unit(const Eigen::Vector3d & a, int k)
{
  for (int j = 0; j < 3; ++j)
    if (std::abs(a[j] - (j == k ? 1.0 : 0.0)) > 1e-15)
      return false;
  return true;
}

static Model build_model(std::istream & in, int & n)
{
  expect(in, "n");
  n = read<int>(in, "n");
  Model model;
  expect(in, "gravity");
  Eigen::Vector3d g;
  for (int j = 0; j < 3; ++j)
    g[j] = read<double>(in, "gravity");
  std::vector<double> armature(n);
  for (int i = 0; i < n; ++i)
  {
    expect(in, "joint");
    const std::string type = read<std::string>(in, "joint type");
    const int parent_line = read<int>(in, "parent");
    if (parent_line < -1 || parent_line >= i)
      fail("joint " + std::to_string(i + 1) + ": the parent must be -1 (base) or an earlier joint");
    const pinocchio::JointIndex parent = pinocchio::JointIndex(parent_line + 1);
    Eigen::Vector3d axis, p, com;
    Eigen::Matrix3d R;
    for (int j = 0; j < 3; ++j)
      axis[j] = read<double>(in, "axis");
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c)
        R(r, c) = read<double>(in, "placement R");
    for (int j = 0; j < 3; ++j)
      p[j] = read<double>(in, "placement p");
    const double mass = read<double>(in, "mass");
    for (int j = 0; j < 3; ++j)
      com[j] = read<double>(in, "com");
    double I[6];  // xx xy xz yy yz zz
    for (int j = 0; j < 6; ++j)
      I[j] = read<double>(in, "inertia");
    armature[i] = read<double>(in, "armature");

    const pinocchio::SE3 placement(R, p);
    const std::string name = "joint" + std::to_string(i + 1);
    pinocchio::JointIndex id;
    if (type == "R")
    {
      if (is_unit(axis, 0))
        id = model.addJoint(parent, pinocchio::JointModelRX(), placement, name);
      else if (is_unit(axis, 1))
        id = model.addJoint(parent, pinocchio::JointModelRY(), placement, name);
      else if (is_unit(axis, 2))
        id = model.addJoint(parent, pinocchio::JointModelRZ(), placement, name);
      else
        id = model.addJoint(parent, pinocchio::JointModelRevoluteUnaligned(axis), placement, name);
    }
    else if (type == "P")
    {
      if (is_unit(axis, 0))
        id = model.addJoint(parent, pinocchio::JointModelPX(), placement, name);
      else if (is_unit(axis, 1))
        id = model.addJoint(parent, pinocchio::JointModelPY(), placement, name);
      else if (is_unit(axis, 2))
        id = model.addJoint(parent, pinocchio::JointModelPZ(), placement, name);
      else
        id = model.addJoint(parent, pinocchio::JointModelPrismaticUnaligned(axis), placement, name);
    }
    else
      fail("joint type must be R or P, not " + type);
    const pinocchio::Symmetric3 Ic(I[0], I[1], I[3], I[2], I[4], I[5]);  // xx xy yy xz yz zz
    if (id != pinocchio::JointIndex(i + 1))
      fail("joint " + std::to_string(i + 1) + " got Pinocchio index " + std::to_string(id));
    model.appendBodyToJoint(id, pinocchio::Inertia(mass, com, Ic), pinocchio::SE3::Identity());
  }
  if (model.nv != n)
    fail("model has nv != n");
  for (int i = 0; i < n; ++i)
    model.armature[i] = armature[i];
  model.gravity.linear(g);
  return model;
}

static double rel_err(const MatrixXd & got, const MatrixXd & want)
{
  const double scale = std::max(1.0, want.cwiseAbs().maxCoeff());
  return (got - want).cwiseAbs().maxCoeff() / scale;
}

static MatrixXd symmetric(MatrixXd A)  // Pinocchio fills the upper triangle of M and M^-1
{
  A.triangularView<Eigen::StrictlyLower>() = A.transpose().triangularView<Eigen::StrictlyLower>();
  return A;
}

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

// ns per call of `body` over `it` calls on states k = 0, 1, ... (cycling: the state changes every
// call), one output element per call accumulated into the volatile sink.
template<typename Body>
static double loop(long it, int nstates, Body && body)
{
  const double s = now_ns();
  int k = 0;
  for (long i = 0; i < it; ++i)
  {
    sink += body(k);
    if (++k == nstates)
      k = 0;
  }
  return (now_ns() - s) / double(it);
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

  expect(in, "nstates");
  const int K = read<int>(in, "nstates");
  std::vector<VectorXd> Q(K, VectorXd(n)), QD(K, VectorXd(n)), QDD(K, VectorXd(n)),
    TAU(K, VectorXd(n));
  for (int k = 0; k < K; ++k)
    for (auto * v : {&Q[k], &QD[k], &QDD[k], &TAU[k]})
      for (int j = 0; j < n; ++j)
        (*v)[j] = read<double>(in, "state");

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
  // calibrate (this also warms up): iterations per repetition for ~target_ns
  std::vector<long> iters(NB);
  for (int b = 0; b < NB; ++b)
  {
    long it = 64;
    double t;
    while ((t = run_bench(b, it) * double(it)) < 0.25 * target_ns)
      it *= 2;
    iters[b] = long(target_ns / (t / double(it))) + 1;
    run_bench(b, iters[b]);
  }
  // repetitions interleaved across the algorithms
  std::vector<std::vector<double>> ns(NB, std::vector<double>(reps));
  for (int r = 0; r < reps; ++r)
    for (int b = 0; b < NB; ++b)
      ns[b][r] = run_bench(b, iters[b]);
  for (int b = 0; b < NB; ++b)
  {
    std::printf("time %s %ld", labels[b], iters[b]);
    for (int r = 0; r < reps; ++r)
      std::printf(" %.3f", ns[b][r]);
    std::printf("\n");
  }
  return 0;
}
