// Pinocchio side of bench/frames.py: one frame's pose and Jacobian, its Jdot*qd and its
// operational-space inertia, computed and timed as Pinocchio's user would.
//
//   pinocchio_frames MODEL.txt check NCHECK     prints the outputs at the first NCHECK states
//   pinocchio_frames MODEL.txt time REPS TARGET_MS
//
// MODEL.txt: the model and the states of bench/pinocchio_harness.cpp (`n`, `gravity`, the joint
// lines, `nstates K` and K states; written by bench/pin_harness.py), then one line
//   frame LINK R00 R01 R02 R10 R11 R12 R20 R21 R22 px py pz
// (LINK: the 0-based joint line the frame is fixed to; (R, p) its placement in that body frame).
//
// Output: `check pose K 16 values` (row-major 4 x 4), `check jacobian K 6N values` (row-major,
// LOCAL_WORLD_ALIGNED), `check jacobian_dot_qd K 6 values` (getFrameClassicalAcceleration at
// a = 0, LOCAL_WORLD_ALIGNED), `check operational_space_inertia K 36 values`; or `time LABEL ...`
// lines as bench/pinocchio_harness.cpp prints them. Timed (each call on the next state):
//   pose_jacobian    forwardKinematics(q) + updateFramePlacement + computeFrameJacobian (LWA)
//   jacobian_only    computeFrameJacobian (LWA) alone (it places the frame's joint itself)
//   jacobian_dot_qd  forwardKinematics(q, v, 0) + getFrameClassicalAcceleration (LWA)
//   operational_space_inertia  computeMinverse + computeFrameJacobian + J M^-1 J^T + its 6 x 6
//                    inverse (Eigen's fixed-size inverse())
// Compiled by bench/frames.py with the flags of bench/pinocchio_harness.cpp.
#include "pinocchio_model.hpp"

#include "pinocchio/algorithm/aba.hpp"
#include "pinocchio/algorithm/frames.hpp"
#include "pinocchio/algorithm/kinematics.hpp"

using Matrix6d = Eigen::Matrix<double, 6, 6>;
using Matrix6Xd = Eigen::Matrix<double, 6, Eigen::Dynamic>;

static pinocchio::FrameIndex add_frame(std::istream & in, Model & model, int n)
{
  expect(in, "frame");
  const int link = read<int>(in, "frame link");
  if (link < 0 || link >= n)
    fail("frame link out of range");
  Eigen::Matrix3d R;
  Eigen::Vector3d p;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c)
      R(r, c) = read<double>(in, "frame R");
  for (int j = 0; j < 3; ++j)
    p[j] = read<double>(in, "frame p");
  const pinocchio::Frame frame(
    "F", pinocchio::JointIndex(link + 1), pinocchio::SE3(R, p), pinocchio::OP_FRAME);
  return model.addFrame(frame);
}

static Matrix6d lambda(const Model & model, Data & data, const VectorXd & q, pinocchio::FrameIndex f, Matrix6Xd & J)
{
  pinocchio::computeMinverse(model, data, q);  // upper triangle of data.Minv
  J.setZero();
  pinocchio::computeFrameJacobian(model, data, q, f, pinocchio::LOCAL_WORLD_ALIGNED, J);
  const Matrix6d inv_lambda = J * data.Minv.selfadjointView<Eigen::Upper>() * J.transpose();
  return inv_lambda.inverse();
}

static void print(const char * label, int k, const double * v, int len)
{
  std::printf("check %s %d", label, k);
  for (int i = 0; i < len; ++i)
    std::printf(" %.17g", v[i]);
  std::printf("\n");
}

int main(int argc, char ** argv)
{
  if (argc < 4)
    fail("usage: pinocchio_frames MODEL.txt check NCHECK | MODEL.txt time REPS TARGET_MS");
  std::ifstream in(argv[1]);
  if (!in)
    fail(std::string("cannot read ") + argv[1]);
  int n = 0;
  Model model = build_model(in, n);
  const States s = read_states(in, n);
  const pinocchio::FrameIndex f = add_frame(in, model, n);
  Data data(model);
  Matrix6Xd J(6, n);
  const VectorXd zero = VectorXd::Zero(n);
  using RowMajor6X = Eigen::Matrix<double, 6, Eigen::Dynamic, Eigen::RowMajor>;

  if (std::string(argv[2]) == "check")
  {
    const int count = std::min(s.K, std::atoi(argv[3]));
    for (int k = 0; k < count; ++k)
    {
      pinocchio::forwardKinematics(model, data, s.Q[k]);
      pinocchio::updateFramePlacement(model, data, f);
      const Eigen::Matrix<double, 4, 4, Eigen::RowMajor> T = data.oMf[f].toHomogeneousMatrix();
      print("pose", k, T.data(), 16);
      J.setZero();
      pinocchio::computeFrameJacobian(model, data, s.Q[k], f, pinocchio::LOCAL_WORLD_ALIGNED, J);
      const RowMajor6X Jr = J;
      print("jacobian", k, Jr.data(), 6 * n);
      pinocchio::forwardKinematics(model, data, s.Q[k], s.QD[k], zero);
      const pinocchio::Motion a =
        pinocchio::getFrameClassicalAcceleration(model, data, f, pinocchio::LOCAL_WORLD_ALIGNED);
      const Eigen::Matrix<double, 6, 1> av = a.toVector();
      print("jacobian_dot_qd", k, av.data(), 6);
      const Eigen::Matrix<double, 6, 6, Eigen::RowMajor> L = lambda(model, data, s.Q[k], f, J);
      print("operational_space_inertia", k, L.data(), 36);
    }
    return 0;
  }
  if (argc != 5 || std::string(argv[2]) != "time")
    fail("usage: pinocchio_frames MODEL.txt check NCHECK | MODEL.txt time REPS TARGET_MS");
  const int reps = std::max(1, std::atoi(argv[3]));
  const double target_ns = 1e6 * std::atof(argv[4]);
  const int K = s.K, last = n - 1;
  const char * labels[] = {"pose_jacobian", "jacobian_only", "jacobian_dot_qd", "operational_space_inertia"};
  auto run_bench = [&](int b, long it) -> double {
    switch (b)
    {
    case 0:
      return loop(it, K, [&](int k) {
        pinocchio::forwardKinematics(model, data, s.Q[k]);
        pinocchio::updateFramePlacement(model, data, f);
        pinocchio::computeFrameJacobian(model, data, s.Q[k], f, pinocchio::LOCAL_WORLD_ALIGNED, J);
        return data.oMf[f].translation()[k % 3] + J(k % 6, last);
      });
    case 1:
      return loop(it, K, [&](int k) {
        pinocchio::computeFrameJacobian(model, data, s.Q[k], f, pinocchio::LOCAL_WORLD_ALIGNED, J);
        return J(k % 6, last);
      });
    case 2:
      return loop(it, K, [&](int k) {
        pinocchio::forwardKinematics(model, data, s.Q[k], s.QD[k], zero);
        return pinocchio::getFrameClassicalAcceleration(model, data, f, pinocchio::LOCAL_WORLD_ALIGNED)
          .toVector()[k % 6];
      });
    case 3:
      return loop(it, K, [&](int k) { return lambda(model, data, s.Q[k], f, J)(k % 6, 0); });
    }
    return -1.0;
  };
  time_benchmarks(labels, 4, run_bench, reps, target_ns);
  return 0;
}
