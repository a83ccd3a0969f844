// The performer's frame: where the drums, the rest tips and the shoulders are, and the
// strokes' places and turns on a kit (gesture_score.hpp).
#include "ictus/score/gesture_score.hpp"

#include <cmath>

namespace ictus
{

namespace
{
constexpr double kPi = 3.14159265358979323846;
} // namespace

PerformerFrame performer_frame_for_drum(const Eigen::Vector3d &membrane_center_m, double radius_m,
                                        double rest_height_m)
{
    PerformerFrame f;
    f.membrane_center_m = membrane_center_m;
    f.membrane_radius_m = radius_m;
    for (int s = 0; s < 2; ++s) {
        const double side = s == static_cast<int>(Side::right) ? 1.0 : -1.0;
        f.rest_tip_m[s] =
            membrane_center_m + side * 0.1 * f.right + rest_height_m * f.up - 0.05 * f.forward;
        f.shoulder_m[s] = membrane_center_m + side * 0.18 * f.right + 0.5 * f.up - 0.45 * f.forward;
    }
    return f;
}

double piece_yaw_rad(const PerformerFrame &frame, int side, const Eigen::Vector3d &strike_m,
                     int drum)
{
    if (drum <= 0 || drum >= static_cast<int>(frame.drums.size()))
        return 0.0;
    const Eigen::Vector3d &sh = frame.shoulder_m[static_cast<size_t>(side & 1)];
    auto heading = [&](const Eigen::Vector3d &p) {
        const Eigen::Vector3d d = p - sh;
        return std::atan2(-d.dot(frame.right), d.dot(frame.forward)); // + toward the left
    };
    double a = heading(strike_m) - heading(frame.membrane_center_m);
    a = std::remainder(a, 2.0 * kPi);
    return std::isfinite(a) ? a : 0.0;
}

Eigen::Vector3d rest_stick_direction(const PerformerFrame &frame, int side)
{
    const double yaw = 40.0 * kPi / 180.0;
    const Eigen::Vector3d inward =
        side == static_cast<int>(Side::right) ? -frame.right : frame.right;
    const Eigen::Vector3d level = std::cos(yaw) * frame.forward + std::sin(yaw) * inward;
    return (kDefaultStickDirection.y() * frame.up + kDefaultStickDirection.z() * level)
        .normalized();
}

Eigen::Vector3d membrane_point(const PerformerFrame &frame, double r_over_a, double theta_deg,
                               int drum)
{
    // docs/osc.md: x_m along world +X, y_m along world -Z.
    const bool kit = drum > 0 && drum < static_cast<int>(frame.drums.size());
    const PerformerFrame::Drum *d = kit ? &frame.drums[static_cast<size_t>(drum)] : nullptr;
    const double radius = d ? d->membrane_radius_m : frame.membrane_radius_m;
    const Eigen::Vector3d &centre = d ? d->membrane_center_m : frame.membrane_center_m;
    const double r = r_over_a * radius, th = theta_deg * kPi / 180.0;
    return centre + Eigen::Vector3d(r * std::cos(th), 0.0, -r * std::sin(th));
}

} // namespace ictus
