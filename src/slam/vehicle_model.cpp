#include <cmath>

#include <priormap/slam/vehicle_model.hpp>

namespace priormap::slam {

Se2 BicycleMotion(const Se2& pose, const BicycleControl& control, double dt, double wheelbase,
                  Mat3* J_pose, Mat32* J_control) {
  const double v = control.speed;
  const double g = control.steer;
  const double heading = pose.theta() + g;
  const double c = std::cos(heading);
  const double s = std::sin(heading);
  if (J_pose) {
    *J_pose << 1.0, 0.0, -v * dt * s,  //
        0.0, 1.0, v * dt * c,          //
        0.0, 0.0, 1.0;
  }
  if (J_control) {
    *J_control << dt * c, -v * dt * s,  //
        dt * s, v * dt * c,             //
        dt * std::sin(g) / wheelbase, v * dt * std::cos(g) / wheelbase;
  }
  return {pose.x() + v * dt * c, pose.y() + v * dt * s,
          pose.theta() + v * dt * std::sin(g) / wheelbase};
}

Se2 IncrementMotion(const Se2& pose, const Se2& increment, Mat3* J_pose, Mat3* J_increment) {
  return pose.Compose(increment, J_pose, J_increment);
}

}  // namespace priormap::slam
