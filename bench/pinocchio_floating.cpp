// Pinocchio side of bench/floating.py: a floating robot (MODEL.txt with a `floating` line, read by
// pinocchio_model.hpp: a free flyer ahead of the joints), checked against symdyn.rnea's numbers and
// timed: rnea, crba and aba on the states of the file.
//
//   pinocchio_floating MODEL.txt REPS TARGET_MS
//
// MODEL.txt: the model (pinocchio_harness.cpp's format, the `floating` line after `gravity`), then
//   nstates K   and K lines q(NQ) v(NV) a(NV) tau(NV)
//   ncheck C    and C lines k tau(NV) M(NV*NV) qdd(NV)   (rnea, crba and aba by symdyn.rnea)
// Output: `check ALGORITHM MAX_RELATIVE_ERROR` and `time ALGORITHM ITERATIONS NS...` lines.
// the thread's CPU time: on a loaded machine, the time slices of other processes are not counted
#define BENCH_CLOCK CLOCK_THREAD_CPUTIME_ID
#include "pinocchio_model.hpp"

#include "pinocchio/algorithm/aba.hpp"
#include "pinocchio/algorithm/crba.hpp"
#include "pinocchio/algorithm/rnea.hpp"

int main(int argc, char ** argv)
{
  if (argc < 2)
    fail("usage: pinocchio_floating MODEL.txt [REPS] [TARGET_MS]");
  std::ifstream in(argv[1]);
  int n = 0;
  Model model = build_model(in, n);
  Data data(model);
  const int nq = model.nq, nv = model.nv;
  expect(in, "nstates");
  const int K = read<int>(in, "nstates");
  std::vector<VectorXd> Q(K, VectorXd(nq)), V(K, VectorXd(nv)), A(K, VectorXd(nv)), T(K, VectorXd(nv));
  for (int k = 0; k < K; ++k)
  {
    for (int j = 0; j < nq; ++j)
      Q[k][j] = read<double>(in, "q");
    for (auto * x : {&V[k], &A[k], &T[k]})
      for (int j = 0; j < nv; ++j)
        (*x)[j] = read<double>(in, "state");
  }
  expect(in, "ncheck");
  const int C = read<int>(in, "ncheck");
  double e_rnea = 0, e_crba = 0, e_aba = 0;
  for (int c = 0; c < C; ++c)
  {
    const int k = read<int>(in, "check state");
    VectorXd tau(nv), qdd(nv);
    MatrixXd M(nv, nv);
    for (int j = 0; j < nv; ++j)
      tau[j] = read<double>(in, "tau");
    for (int r = 0; r < nv; ++r)
      for (int j = 0; j < nv; ++j)
        M(r, j) = read<double>(in, "M");
    for (int j = 0; j < nv; ++j)
      qdd[j] = read<double>(in, "qdd");
    e_rnea = std::max(e_rnea, rel_err(pinocchio::rnea(model, data, Q[k], V[k], A[k]), tau));
    e_crba = std::max(e_crba, rel_err(symmetric(pinocchio::crba(model, data, Q[k])), M));
    e_aba = std::max(e_aba, rel_err(pinocchio::aba(model, data, Q[k], V[k], T[k]), qdd));
  }
  std::printf("info joints %d nv %d pinocchio %s\n", n, nv, PINOCCHIO_VERSION);
  std::printf("check rnea %.3e\ncheck crba %.3e\ncheck aba %.3e\n", e_rnea, e_crba, e_aba);
  const int reps = argc > 2 ? std::atoi(argv[2]) : 11;
  const double target_ns = 1e6 * (argc > 3 ? std::atof(argv[3]) : 2.0);
  static const char * labels[] = {"rnea", "crba", "aba"};
  auto run_bench = [&](int b, long it) {
    switch (b)
    {
    case 0:
      return loop(it, K, [&](int k) { return pinocchio::rnea(model, data, Q[k], V[k], A[k])[0]; });
    case 1:
      return loop(it, K, [&](int k) { return pinocchio::crba(model, data, Q[k])(0, nv - 1); });
    default:
      return loop(it, K, [&](int k) { return pinocchio::aba(model, data, Q[k], V[k], T[k])[0]; });
    }
  };
  time_benchmarks(labels, 3, run_bench, reps, target_ns);
  return 0;
}
