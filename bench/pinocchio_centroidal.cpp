// Pinocchio side of bench/floating_centroidal.py: the centroidal momentum matrix and its time
// variation of a floating robot, computed and timed as Pinocchio's user would.
//
//   pinocchio_centroidal MODEL.txt check NCHECK     prints Ag and dAg*v at the first NCHECK states
//   pinocchio_centroidal MODEL.txt time REPS TARGET_MS
//
// MODEL.txt: the floating model of bench/pinocchio_model.hpp (`n`, `gravity`, the line
// `floating MASS CX CY CZ IXX IXY IXZ IYY IYZ IZZ` of the base body, the joint lines), then
// `nstates K` and K lines q(7 + n) v(6 + n) in Pinocchio's free-flyer conventions.
//
// Timed (each call on the next state):
//   centroidal_map                 computeCentroidalMap(q)
//   centroidal_map_time_variation  computeCentroidalMapTimeVariation(q, v) and dAg * v
// the thread's CPU time: on a loaded machine, the time slices of other processes are not counted
#define BENCH_CLOCK CLOCK_THREAD_CPUTIME_ID
#include "pinocchio_model.hpp"

#include "pinocchio/algorithm/centroidal.hpp"

int main(int argc, char ** argv)
{
  if (argc < 4)
    fail("usage: pinocchio_centroidal MODEL.txt check NCHECK | time REPS TARGET_MS");
  std::ifstream in(argv[1]);
  int n = 0;
  const Model model = build_model(in, n);
  if (model.nv != n + 6)
    fail("MODEL.txt: no floating base");
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
