// Pinocchio side of bench/closed_loops.py: the forward dynamics of a robot with closed loops by
// pinocchio::constraintDynamics (RigidConstraintModel, CONTACT_3D per loop), as Pinocchio's user
// would write it.
//
//   pinocchio_loops MODEL.txt check NCHECK     prints ddq at the first NCHECK states
//   pinocchio_loops MODEL.txt time REPS TARGET_MS
//
// MODEL.txt: the model and the states of bench/pinocchio_harness.cpp (`n`, `gravity`, the joint
// lines, `nstates K` and K states q qd qdd tau: closed configurations, rates on the closure and
// tau zero on the passive joints; written by bench/closed_loops.py), then `nloops L` and L lines
//   loop LINK_A ax ay az LINK_B bx by bz
// (LINK: the 0-based joint line the point is fixed to, -1 the base; the point in that body frame).
//
// Output: `check ddq K N values`, or the `time LABEL ...` lines of bench/pinocchio_model.hpp for
//   constraint_dynamics  constraintDynamics(q, qd, tau) (initConstraintDynamics once, before)
#include "pinocchio_model.hpp"

#include "pinocchio/algorithm/constrained-dynamics.hpp"
#if __has_include("pinocchio/constraints.hpp")  // pinocchio >= 4
  #include "pinocchio/constraints.hpp"
#endif

using Constraint = pinocchio::RigidConstraintModel;
using ConstraintData = pinocchio::RigidConstraintData;
using Constraints = PINOCCHIO_STD_VECTOR_WITH_EIGEN_ALLOCATOR(Constraint);
using ConstraintDatas = PINOCCHIO_STD_VECTOR_WITH_EIGEN_ALLOCATOR(ConstraintData);

static Constraints read_loops(std::istream & in, const Model & model, int n)
{
  expect(in, "nloops");
  const int L = read<int>(in, "nloops");
  Constraints out;
  for (int l = 0; l < L; ++l)
  {
    expect(in, "loop");
    int link[2];
    Eigen::Vector3d point[2];
    for (int s = 0; s < 2; ++s)
    {
      link[s] = read<int>(in, "loop link");
      if (link[s] < -1 || link[s] >= n)
        fail("loop link out of range");
      for (int j = 0; j < 3; ++j)
        point[s][j] = read<double>(in, "loop point");
    }
    out.push_back(Constraint(
      pinocchio::CONTACT_3D, model, pinocchio::JointIndex(link[0] + 1),
      pinocchio::SE3(Eigen::Matrix3d::Identity(), point[0]), pinocchio::JointIndex(link[1] + 1),
      pinocchio::SE3(Eigen::Matrix3d::Identity(), point[1]), pinocchio::LOCAL));
  }
  return out;
}

int main(int argc, char ** argv)
{
  if (argc < 4)
    fail("usage: pinocchio_loops MODEL.txt check NCHECK | MODEL.txt time REPS TARGET_MS");
  std::ifstream in(argv[1]);
  if (!in)
    fail(std::string("cannot read ") + argv[1]);
  int n = 0;
  Model model = build_model(in, n);
  const States s = read_states(in, n);
  const Constraints constraints = read_loops(in, model, n);
  ConstraintDatas datas;
  for (const auto & c : constraints)
    datas.push_back(ConstraintData(c));
  Data data(model);
  pinocchio::initConstraintDynamics(model, data, constraints, datas);
  pinocchio::ProximalSettings settings(1e-14, 1e-10, 100);
  const std::string mode = argv[2];
  if (mode == "check")
  {
    const int K = std::min(std::atoi(argv[3]), s.K);
    for (int k = 0; k < K; ++k)
    {
      const VectorXd ddq =
        pinocchio::constraintDynamics(model, data, s.Q[k], s.QD[k], s.TAU[k], constraints, datas, settings);
      std::printf("check ddq %d", k);
      for (int i = 0; i < n; ++i)
        std::printf(" %.17g", ddq[i]);
      std::printf("\n");
    }
    return 0;
  }
  if (mode != "time" || argc < 5)
    fail("usage: pinocchio_loops MODEL.txt time REPS TARGET_MS");
  const int reps = std::atoi(argv[3]);
  const double target_ns = 1e6 * std::atof(argv[4]);
  const char * labels[] = {"constraint_dynamics"};
  time_benchmarks(
    labels, 1,
    [&](int, long it) {
      return loop(it, s.K, [&](int k) {
        return pinocchio::constraintDynamics(
          model, data, s.Q[k], s.QD[k], s.TAU[k], constraints, datas, settings)[0];
      });
    },
    reps, target_ns);
  return 0;
}
