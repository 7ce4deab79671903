// Pinocchio side of bench/floating_centroidal.py: the centroidal momentum matrix and its time
// variation of a floating robot, computed and timed as Pinocchio's user would.
//
//   pinocchio_centroidal MODEL.txt check NCHECK     prints Ag and dAg*v at the first NCHECK states
//   pinocchio_centroidal MODEL.txt time REPS TARGET_MS
//
// MODEL.txt: `n`, `gravity` and the joint lines of bench/pinocchio_harness.cpp (the joints below
// the base, parent -1 being the base), then
//   base MASS CX CY CZ IXX IXY IXZ IYY IYZ IZZ        (the base body, base frame, about its CoM)
//   nstates K
// and K lines q(7 + n) v(6 + n) in Pinocchio's free-flyer conventions. The model is a
// JointModelFreeFlyer carrying the base body, with the joints of bench/pinocchio_model.hpp's
// build_model re-attached below it.
//
// Timed (each call on the next state):
//   centroidal_map                 computeCentroidalMap(q)
//   centroidal_map_time_variation  computeCentroidalMapTimeVariation(q, v) and dAg * v
#include "pinocchio_model.hpp"

#include "pinocchio/algorithm/centroidal.hpp"

static Model floating_model(std::istream & in, int & n)
{
  const Model fixed = build_model(in, n);
  Model model;
  const pinocchio::JointIndex base =
    model.addJoint(0, pinocchio::JointModelFreeFlyer(), pinocchio::SE3::Identity(), "base");
  expect(in, "base");
  const double mass = read<double>(in, "base mass");
  Eigen::Vector3d com;
  for (int j = 0; j < 3; ++j)
    com[j] = read<double>(in, "base com");
  double I[6];  // xx xy xz yy yz zz
  for (int j = 0; j < 6; ++j)
    I[j] = read<double>(in, "base inertia");
  model.appendBodyToJoint(
    base, pinocchio::Inertia(mass, com, pinocchio::Symmetric3(I[0], I[1], I[3], I[2], I[4], I[5])),
    pinocchio::SE3::Identity());
  for (pinocchio::JointIndex i = 1; i < fixed.joints.size(); ++i)
  {
    const pinocchio::JointIndex parent = fixed.parents[i] + 1;
    const pinocchio::JointIndex id =
      model.addJoint(parent, fixed.joints[i], fixed.jointPlacements[i], fixed.names[i]);
    model.appendBodyToJoint(id, fixed.inertias[i], pinocchio::SE3::Identity());
  }
  model.gravity = fixed.gravity;
  return model;
}

int main(int argc, char ** argv)
{
  if (argc < 4)
    fail("usage: pinocchio_centroidal MODEL.txt check NCHECK | time REPS TARGET_MS");
  std::ifstream in(argv[1]);
  int n = 0;
  const Model model = floating_model(in, n);
  Data data(model);
  expect(in, "nstates");
  const int K = read<int>(in, "nstates");
  std::vector<VectorXd> Q(K, VectorXd(model.nq)), V(K, VectorXd(model.nv));
  for (int k = 0; k < K; ++k)
  {
    for (int j = 0; j < model.nq; ++j)
      Q[k][j] = read<double>(in, "q");
    for (int j = 0; j < model.nv; ++j)
      V[k][j] = read<double>(in, "v");
  }
  const std::string mode = argv[2];
  if (mode == "check")
  {
    const int ncheck = std::min(K, std::atoi(argv[3]));
    for (int k = 0; k < ncheck; ++k)
    {
      const MatrixXd Ag = pinocchio::computeCentroidalMap(model, data, Q[k]);
      std::printf("check Ag %d", k);
      for (int r = 0; r < 6; ++r)
        for (int c = 0; c < model.nv; ++c)
          std::printf(" %.17g", Ag(r, c));
      std::printf("\n");
      pinocchio::computeCentroidalMapTimeVariation(model, data, Q[k], V[k]);
      const VectorXd drift = data.dAg * V[k];
      std::printf("check drift %d", k);
      for (int r = 0; r < 6; ++r)
        std::printf(" %.17g", drift[r]);
      std::printf("\n");
    }
    return 0;
  }
  if (mode != "time" || argc < 5)
    fail("usage: pinocchio_centroidal MODEL.txt time REPS TARGET_MS");
  const int reps = std::atoi(argv[3]);
  const double target_ns = 1e6 * std::atof(argv[4]);
  const char * labels[] = {"centroidal_map", "centroidal_map_time_variation"};
  auto run_bench = [&](int b, long it) -> double {
    if (b == 0)
      return loop(it, K, [&](int k) { return pinocchio::computeCentroidalMap(model, data, Q[k])(0, 0); });
    return loop(it, K, [&](int k) {
      pinocchio::computeCentroidalMapTimeVariation(model, data, Q[k], V[k]);
      return (data.dAg * V[k])[0];
    });
  };
  time_benchmarks(labels, 2, run_bench, reps, target_ns);
  return 0;
}
