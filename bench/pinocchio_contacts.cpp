// Pinocchio side of bench/contacts.py: a floating robot (MODEL.txt with a `floating` line, read by
// pinocchio_model.hpp: a free flyer ahead of the joints) in contact at frames of its links, checked
// against symdyn's numeric oracle (symdyn.oracle.contacts) and timed: constraintDynamics,
// impulseDynamics and their derivatives (computeConstraintDynamicsDerivatives,
// computeImpulseDynamicsDerivatives, each after the dynamics it differentiates, as a user calls them).
//
//   pinocchio_contacts MODEL.txt [REPS] [TARGET_MS]
//
// MODEL.txt: the model (pinocchio_harness.cpp's format, the `floating` line after `gravity`), then
//   ncontact C   and C lines `contact KIND LINK R(9) p(3)`: KIND 3 (point: CONTACT_3D,
//                LOCAL_WORLD_ALIGNED) or 6 (CONTACT_6D, LOCAL), LINK symdyn's link index (-1 the
//                base), R p the frame's placement in the link's body frame
//   nstates K    and K lines q(NQ) v(NV) tau(NV)
//   ncheck C     and C lines k qdd(NV) lambda(NL) qd_plus(NV) impulse(NL) dqdd_dq(NV*NV)
//                dlambda_dq(NL*NV) dqd_plus_dq(NV*NV) dimpulse_dq(NL*NV): the oracle's, restitution 0
// Output: `check NAME MAX_RELATIVE_ERROR` and `time NAME ITERATIONS NS...` lines.
// the thread's CPU time: on a loaded machine, the time slices of other processes are not counted
#define BENCH_CLOCK CLOCK_THREAD_CPUTIME_ID
#include "pinocchio_model.hpp"

#include "pinocchio/algorithm/constrained-dynamics.hpp"
#include "pinocchio/algorithm/constrained-dynamics-derivatives.hpp"
#include "pinocchio/algorithm/impulse-dynamics.hpp"
#include "pinocchio/algorithm/impulse-dynamics-derivatives.hpp"

using Constraint = pinocchio::RigidConstraintModel;
using ConstraintData = pinocchio::RigidConstraintData;
using Constraints = PINOCCHIO_STD_VECTOR_WITH_EIGEN_ALLOCATOR(Constraint);
using ConstraintDatas = PINOCCHIO_STD_VECTOR_WITH_EIGEN_ALLOCATOR(ConstraintData);

static MatrixXd read_matrix(std::istream & in, int rows, int cols, const char * what)
{
  MatrixXd m(rows, cols);
  for (int r = 0; r < rows; ++r)
    for (int c = 0; c < cols; ++c)
      m(r, c) = read<double>(in, what);
  return m;
}

int main(int argc, char ** argv)
{
  if (argc < 2)
    fail("usage: pinocchio_contacts MODEL.txt [REPS] [TARGET_MS]");
  std::ifstream in(argv[1]);
  int n = 0;
  Model model = build_model(in, n);
  Data data(model);
  const int nq = model.nq, nv = model.nv;
  if (nv != n + 6)
    fail("the contacts harness takes a floating robot");
  expect(in, "ncontact");
  const int ncontact = read<int>(in, "ncontact");
  Constraints constraints;
  int nl = 0;
  for (int c = 0; c < ncontact; ++c)
  {
    expect(in, "contact");
    const int kind = read<int>(in, "kind");
    const int link = read<int>(in, "link");
    if ((kind != 3 && kind != 6) || link < -1 || link >= n)
      fail("contact " + std::to_string(c) + ": kind 3 or 6, link -1 .. n-1");
    const MatrixXd R = read_matrix(in, 3, 3, "contact R");
    const MatrixXd p = read_matrix(in, 3, 1, "contact p");
    const pinocchio::SE3 placement{Eigen::Matrix3d(R), Eigen::Vector3d(p)};
    const auto joint = pinocchio::JointIndex(link + 2);  // the free flyer is joint 1, link 0 joint 2
    if (kind == 3)
      constraints.push_back(Constraint(pinocchio::CONTACT_3D, model, joint, placement, pinocchio::LOCAL_WORLD_ALIGNED));
    else
      constraints.push_back(Constraint(pinocchio::CONTACT_6D, model, joint, placement, pinocchio::LOCAL));
    nl += kind;
  }
  ConstraintDatas datas;
  for (const auto & c : constraints)
    datas.push_back(ConstraintData(c));
  pinocchio::initConstraintDynamics(model, data, constraints, datas);
  pinocchio::ProximalSettings prox(1e-12, 0.0, 1);  // no proximal damping, one iteration (exact solve)

  expect(in, "nstates");
  const int K = read<int>(in, "nstates");
  std::vector<VectorXd> Q(K, VectorXd(nq)), V(K, VectorXd(nv)), T(K, VectorXd(nv));
  for (int k = 0; k < K; ++k)
  {
    for (int j = 0; j < nq; ++j)
      Q[k][j] = read<double>(in, "q");
    for (auto * x : {&V[k], &T[k]})
      for (int j = 0; j < nv; ++j)
        (*x)[j] = read<double>(in, "state");
  }
  expect(in, "ncheck");
  const int C = read<int>(in, "ncheck");
  double e[8] = {0, 0, 0, 0, 0, 0, 0, 0};
  for (int c = 0; c < C; ++c)
  {
    const int k = read<int>(in, "check state");
    const MatrixXd qdd = read_matrix(in, nv, 1, "qdd"), lambda = read_matrix(in, nl, 1, "lambda");
    const MatrixXd plus = read_matrix(in, nv, 1, "qd_plus"), impulse = read_matrix(in, nl, 1, "impulse");
    const MatrixXd dqdd = read_matrix(in, nv, nv, "dqdd_dq"), dlambda = read_matrix(in, nl, nv, "dlambda_dq");
    const MatrixXd dplus = read_matrix(in, nv, nv, "dqd_plus_dq"), dimpulse = read_matrix(in, nl, nv, "dimpulse_dq");
    e[0] = std::max(e[0], rel_err(pinocchio::constraintDynamics(model, data, Q[k], V[k], T[k], constraints, datas, prox), qdd));
    e[1] = std::max(e[1], rel_err(data.lambda_c, lambda));
    pinocchio::computeConstraintDynamicsDerivatives(model, data, constraints, datas, prox);
    e[2] = std::max(e[2], rel_err(data.ddq_dq, dqdd));
    e[3] = std::max(e[3], rel_err(data.dlambda_dq, dlambda));
    e[4] = std::max(e[4], rel_err(pinocchio::impulseDynamics(model, data, Q[k], V[k], constraints, datas, 0.0, prox), plus));
    e[5] = std::max(e[5], rel_err(data.impulse_c, impulse));
    pinocchio::computeImpulseDynamicsDerivatives(model, data, constraints, datas, 0.0, prox);
    e[6] = std::max(e[6], rel_err(data.ddq_dq, dplus));
    e[7] = std::max(e[7], rel_err(data.dlambda_dq, dimpulse));
  }
  static const char * checks[] = {"qdd", "lambda", "dqdd_dq", "dlambda_dq", "qd_plus", "impulse", "dqd_plus_dq", "dimpulse_dq"};
  std::printf("info joints %d nv %d nlambda %d pinocchio %s\n", n, nv, nl, PINOCCHIO_VERSION);
  for (int j = 0; j < 8; ++j)
    std::printf("check %s %.3e\n", checks[j], e[j]);
  const int reps = argc > 2 ? std::atoi(argv[2]) : 11;
  const double target_ns = 1e6 * (argc > 3 ? std::atof(argv[3]) : 2.0);
  static const char * labels[] = {"constraintDynamics", "impulseDynamics", "constraintDynamicsDerivatives", "impulseDynamicsDerivatives"};
  auto run_bench = [&](int b, long it) {
    switch (b)
    {
    case 0:
      return loop(it, K, [&](int k) { return pinocchio::constraintDynamics(model, data, Q[k], V[k], T[k], constraints, datas, prox)[0]; });
    case 1:
      return loop(it, K, [&](int k) { return pinocchio::impulseDynamics(model, data, Q[k], V[k], constraints, datas, 0.0, prox)[0]; });
    case 2:
      return loop(it, K, [&](int k) {
        pinocchio::constraintDynamics(model, data, Q[k], V[k], T[k], constraints, datas, prox);
        pinocchio::computeConstraintDynamicsDerivatives(model, data, constraints, datas, prox);
        return data.ddq_dq(0, 0);
      });
    default:
      return loop(it, K, [&](int k) {
        pinocchio::impulseDynamics(model, data, Q[k], V[k], constraints, datas, 0.0, prox);
        pinocchio::computeImpulseDynamicsDerivatives(model, data, constraints, datas, 0.0, prox);
        return data.ddq_dq(0, 0);
      });
    }
  };
  time_benchmarks(labels, 4, run_bench, reps, target_ns);
  return 0;
}
