// Shared by bench's Pinocchio harnesses (pinocchio_harness.cpp, pinocchio_frames.cpp): the model
// of MODEL.txt (its format: pinocchio_harness.cpp), the states, the timing loop and protocol.
#pragma once
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

using pinocchio::Data;
using pinocchio::Model;
using Eigen::MatrixXd;
using Eigen::VectorXd;

static volatile double sink;

// The clock of the timing loops: wall time by default; a harness may define BENCH_CLOCK as
// CLOCK_THREAD_CPUTIME_ID before including this header, so that the time the scheduler gives to
// other processes on a loaded machine is not counted (bench/floating.py).
#ifndef BENCH_CLOCK
#define BENCH_CLOCK CLOCK_MONOTONIC
#endif

static double now_ns()
{
  timespec t;
  clock_gettime(BENCH_CLOCK, &t);
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
  // optional: `floating mass cx cy cz Ixx Ixy Ixz Iyy Iyz Izz`, a free flyer (Pinocchio's joint 1)
  // carrying the base body, ahead of the joints (bench/floating.py)
  int first = 1;
  in >> std::ws;
  if (in.peek() == 'f')
  {
    expect(in, "floating");
    const double mass = read<double>(in, "base mass");
    Eigen::Vector3d com;
    for (int j = 0; j < 3; ++j)
      com[j] = read<double>(in, "base com");
    double I[6];
    for (int j = 0; j < 6; ++j)
      I[j] = read<double>(in, "base inertia");
    const auto id = model.addJoint(0, pinocchio::JointModelFreeFlyer(), pinocchio::SE3::Identity(), "root");
    model.appendBodyToJoint(id, pinocchio::Inertia(mass, com, pinocchio::Symmetric3(I[0], I[1], I[3], I[2], I[4], I[5])));
    first = 2;
  }
  for (int i = 0; i < n; ++i)
  {
    expect(in, "joint");
    const std::string type = read<std::string>(in, "joint type");
    const int parent_line = read<int>(in, "parent");
    if (parent_line < -1 || parent_line >= i)
      fail("joint " + std::to_string(i + 1) + ": the parent must be -1 (base) or an earlier joint");
    const pinocchio::JointIndex parent = pinocchio::JointIndex(parent_line + first);
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
    if (id != pinocchio::JointIndex(i + first))
      fail("joint " + std::to_string(i + 1) + " got Pinocchio index " + std::to_string(id));
    model.appendBodyToJoint(id, pinocchio::Inertia(mass, com, Ic), pinocchio::SE3::Identity());
  }
  const int base = first == 2 ? 6 : 0;
  if (model.nv != n + base)
    fail("model has nv != n (+ 6 on a floating base)");
  for (int i = 0; i < n; ++i)
    model.armature[base + i] = armature[i];
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

// The K states of MODEL.txt after the model: `nstates K`, then K lines q(N) qd(N) qdd(N) tau(N).
struct States
{
  int K = 0;
  std::vector<VectorXd> Q, QD, QDD, TAU;
};

static States read_states(std::istream & in, int n)
{
  States s;
  expect(in, "nstates");
  s.K = read<int>(in, "nstates");
  s.Q.assign(s.K, VectorXd(n));
  s.QD.assign(s.K, VectorXd(n));
  s.QDD.assign(s.K, VectorXd(n));
  s.TAU.assign(s.K, VectorXd(n));
  for (int k = 0; k < s.K; ++k)
    for (auto * v : {&s.Q[k], &s.QD[k], &s.QDD[k], &s.TAU[k]})
      for (int j = 0; j < n; ++j)
        (*v)[j] = read<double>(in, "state");
  return s;
}

// The timing protocol of bench/run.py's harnesses: calibrate each of the NB benchmarks (this also
// warms up) to iterations per repetition of ~target_ns, then `reps` repetitions interleaved across
// them; prints `time LABEL ITERATIONS NS_PER_CALL_REP1 ...` per benchmark.
template<typename RunBench>
static void time_benchmarks(const char * const * labels, int NB, RunBench && run_bench, int reps, double target_ns)
{
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
}
