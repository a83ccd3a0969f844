// Joint-space PD (eq. 1) as ODE motor rows; default gains and torque limits.
#include "ictus/control/joint_controller.hpp"
#include "ictus/base/rotation.hpp"

#include <cmath>
#include <cstring>
#include <sstream>

namespace ictus
{

namespace
{
struct TorqueRow {
    const char *suffix; // joint name without the l_/r_ prefix
    double nm;          // per axis, for a 70 kg adult
};
// Order-of-magnitude maximal voluntary isometric torques of an adult, rounded:
// a lumbar spine holds the whole upper body, a wrist only a hand and a stick.
// The clavicle is the exception: a short, light segment between thorax and
// arm, it must react whatever the shoulder applies plus the arm's weight, so
// its limit exceeds the shoulder's (at 60 N m it saturated a third of the
// time on the CMU clip, limiting the arm).
const TorqueRow kTorque[] = {
    {"lumbar", 250.0}, {"thorax", 250.0},   {"neck", 40.0},     {"upper_neck", 30.0},
    {"head", 20.0},    {"clavicle", 120.0}, {"shoulder", 90.0}, {"elbow", 70.0},
    {"wrist", 15.0},   {"hip", 200.0},      {"knee", 200.0},    {"ankle", 150.0},
};
} // namespace

double default_torque_limit_nm(const std::string &joint_name, double body_mass_kg)
{
    std::string base = joint_name;
    if (base.rfind("l_", 0) == 0 || base.rfind("r_", 0) == 0)
        base = base.substr(2);
    for (const TorqueRow &row : kTorque)
        if (base == row.suffix)
            return row.nm * body_mass_kg / 70.0;
    throw ControlError("torque limit: unknown joint '" + joint_name + "'");
}

std::vector<JointGains> default_gains(const CharacterModel &model, const CharacterPose &pose,
                                      const GainOptions &options)
{
    auto bad = [](const char *what, double v) {
        std::ostringstream s;
        s << what << ": expected a finite value > 0, got " << v;
        return ControlError(s.str());
    };
    if (!(std::isfinite(options.natural_frequency_hz) && options.natural_frequency_hz > 0.0))
        throw bad("gain natural frequency (Hz)", options.natural_frequency_hz);
    if (!(std::isfinite(options.damping_ratio) && options.damping_ratio > 0.0))
        throw bad("damping ratio", options.damping_ratio);
    if (!(std::isfinite(options.torque_scale) && options.torque_scale > 0.0))
        throw bad("torque scale", options.torque_scale);
    const double w = 2.0 * M_PI * options.natural_frequency_hz;
    std::vector<JointGains> gains(CharacterModel::kJoints);
    for (int j = 0; j < CharacterModel::kJoints; ++j) {
        const double inertia = model.subtree_inertia(j, pose).inertia_kg_m2;
        gains[j].kp_nm_per_rad = inertia * w * w;
        gains[j].kd_nm_s_per_rad = 2.0 * options.damping_ratio * inertia * w;
        gains[j].torque_limit_nm =
            options.torque_scale *
            default_torque_limit_nm(model.joint_name(j), model.options().body_mass_kg);
    }
    return gains;
}

void apply_gain_overrides(const CharacterModel &model, const nlohmann::json &overrides,
                          const std::string &source, std::vector<JointGains> &gains)
{
    if (!overrides.is_object())
        throw ControlError(source + ": expected a JSON object {joint: {field: value}}");
    if (gains.size() != static_cast<size_t>(CharacterModel::kJoints))
        throw ControlError(source + ": gains must cover the 19 joints");
    for (auto it = overrides.begin(); it != overrides.end(); ++it) {
        const int j = model.joint_index(it.key());
        if (j < 0)
            throw ControlError(source + ": unknown joint '" + it.key() + "'");
        if (!it.value().is_object())
            throw ControlError(source + ": joint '" + it.key() + "': expected an object");
        for (auto f = it.value().begin(); f != it.value().end(); ++f) {
            double *field = nullptr;
            if (f.key() == "kp_nm_per_rad")
                field = &gains[j].kp_nm_per_rad;
            else if (f.key() == "kd_nm_s_per_rad")
                field = &gains[j].kd_nm_s_per_rad;
            else if (f.key() == "torque_limit_nm")
                field = &gains[j].torque_limit_nm;
            else
                throw ControlError(source + ": joint '" + it.key() + "': unknown field '" +
                                   f.key() + "' (kp_nm_per_rad, kd_nm_s_per_rad, torque_limit_nm)");
            if (!f.value().is_number() || !std::isfinite(f.value().get<double>()) ||
                f.value().get<double>() <= 0.0)
                throw ControlError(source + ": joint '" + it.key() + "': " + f.key() +
                                   " must be a finite number > 0, got " + f.value().dump());
            *field = f.value().get<double>();
        }
    }
}

nlohmann::json gains_to_json(const CharacterModel &model, const std::vector<JointGains> &gains)
{
    nlohmann::json j = nlohmann::json::object();
    for (size_t i = 0; i < gains.size(); ++i)
        j[model.joint_name(static_cast<int>(i))] = {{"kp_nm_per_rad", gains[i].kp_nm_per_rad},
                                                    {"kd_nm_s_per_rad", gains[i].kd_nm_s_per_rad},
                                                    {"torque_limit_nm", gains[i].torque_limit_nm}};
    return j;
}

MotorCommand pd_motor_command(const Eigen::Quaterniond &parent_world,
                              const Eigen::Quaterniond &child_world,
                              const Eigen::Quaterniond &target_local,
                              const Eigen::Vector3d &target_rate_parent, const JointGains &gains,
                              bool rate_feedforward)
{
    MotorCommand cmd;
    const Eigen::Quaterniond current_local = parent_world.conjugate() * child_world;
    // The error rotation acts on the left (parent frame): q_T = q_e q_S.
    cmd.error_parent = log_map(target_local * current_local.conjugate());
    Eigen::Vector3d rate = (gains.kp_nm_per_rad / gains.kd_nm_s_per_rad) * cmd.error_parent;
    if (rate_feedforward)
        rate += target_rate_parent;
    cmd.velocity_world = parent_world * rate;
    cmd.cfm = 1.0 / gains.kd_nm_s_per_rad;
    cmd.fmax = gains.torque_limit_nm;
    return cmd;
}

void scale_gains(const std::vector<JointGains> &base, const double scale[2],
                 std::vector<JointGains> &gains)
{
    gains = base;
    for (JointGains &g : gains) {
        g.kp_nm_per_rad *= scale[0];
        g.kd_nm_s_per_rad *= scale[1];
    }
}

} // namespace ictus
