// joint_limits.cpp -- the paper's two joint-limit formulations ("Virtual
// Character Modeling"): Euler-angle statistics, and Algorithm 1 (tangent space
// of the mean quaternion, SVD, ellipsoid of k standard deviations).
#include "ictus/mocap/joint_limits.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <iomanip>
#include <ostream>
#include <sstream>

namespace ictus
{

namespace
{

constexpr double kPi = 3.14159265358979323846;
constexpr double kRadToDeg = 180.0 / kPi;

double wrap_angle(double angle_rad)
{
    double wrapped = std::remainder(angle_rad, 2.0 * kPi); // [-pi, pi]
    if (wrapped <= -kPi)
        wrapped += 2.0 * kPi;
    return wrapped;
}

void check_series(const std::vector<Eigen::Quaterniond> &series, const char *who)
{
    if (series.empty())
        throw MocapError(who, 0, "expected at least one rotation, got none");
    for (std::size_t i = 0; i < series.size(); ++i) {
        const double norm = series[i].coeffs().norm();
        if (!std::isfinite(norm) || norm < 1e-9)
            throw MocapError(who, 0,
                             "expected finite non-zero quaternions, got norm " +
                                 std::to_string(norm) + " at sample " + std::to_string(i));
    }
}

// Linear-interpolated percentile (0..100) of sorted values.
double percentile_of_sorted(const std::vector<double> &sorted, double percent)
{
    const double position = percent / 100.0 * static_cast<double>(sorted.size() - 1);
    const auto below = static_cast<std::size_t>(std::floor(position));
    const std::size_t above = std::min(below + 1, sorted.size() - 1);
    const double u = position - static_cast<double>(below);
    return (1.0 - u) * sorted[below] + u * sorted[above];
}

nlohmann::json vector_json(const Eigen::Vector3d &v)
{
    return {v.x(), v.y(), v.z()};
}

Eigen::Vector3d vector_from_json(const nlohmann::json &j, const char *key)
{
    if (!j.contains(key) || !j[key].is_array() || j[key].size() != 3)
        throw MocapError("joint limit JSON", 0,
                         std::string("expected \"") + key + "\" as an array of 3 numbers");
    Eigen::Vector3d v;
    for (int k = 0; k < 3; ++k) {
        if (!j[key][static_cast<std::size_t>(k)].is_number())
            throw MocapError("joint limit JSON", 0,
                             std::string("expected numbers in \"") + key + "\"");
        v[k] = j[key][static_cast<std::size_t>(k)].get<double>();
        if (!std::isfinite(v[k]))
            throw MocapError("joint limit JSON", 0,
                             std::string("expected finite numbers in \"") + key + "\"");
    }
    return v;
}

const char *method_name(EulerLimitOptions::Method method)
{
    return method == EulerLimitOptions::Method::mean_std ? "mean_std" : "percentile";
}

} // namespace

// ---- Euler ------------------------------------------------------------------

Eigen::Vector3d EulerLimit::angles(const Eigen::Quaterniond &q) const
{
    // a0 and a2 are circular: unwrap them around the middle of the range so a
    // range across +/-pi works. a1 lives in [-pi/2, pi/2] and never wraps.
    Eigen::Vector3d a = euler_angles(q, order);
    for (int k : {0, 2}) {
        const double centre = 0.5 * (lower_rad[k] + upper_rad[k]);
        a[k] = centre + wrap_angle(a[k] - centre);
    }
    return a;
}

bool EulerLimit::contains(const Eigen::Quaterniond &q, double tolerance_rad) const
{
    const Eigen::Vector3d a = angles(q);
    for (int k = 0; k < 3; ++k)
        if (a[k] < lower_rad[k] - tolerance_rad || a[k] > upper_rad[k] + tolerance_rad)
            return false;
    return true;
}

Eigen::Quaterniond EulerLimit::clamp(const Eigen::Quaterniond &q) const
{
    if (contains(q, 0.0))
        return q.normalized(); // untouched: recomposing would only add rounding
    Eigen::Vector3d a = angles(q);
    for (int k = 0; k < 3; ++k)
        a[k] = std::clamp(a[k], lower_rad[k], upper_rad[k]);
    return from_euler(a, order);
}

EulerLimit learn_euler_limit(const std::vector<Eigen::Quaterniond> &series,
                             const EulerLimitOptions &options)
{
    check_series(series, "learn_euler_limit");
    if (!std::isfinite(options.k) || options.k < 0.0)
        throw MocapError("learn_euler_limit", 0,
                         "expected k finite and >= 0, got " + std::to_string(options.k));
    if (!(options.percentile >= 0.0 && options.percentile < 50.0))
        throw MocapError("learn_euler_limit", 0,
                         "expected percentile in [0, 50), got " +
                             std::to_string(options.percentile));
    const std::size_t n = series.size();
    std::vector<Eigen::Vector3d> angles(n);
    for (std::size_t i = 0; i < n; ++i)
        angles[i] = euler_angles(series[i], options.order);
    // Unwrap a0 and a2 around their circular mean before taking statistics.
    for (int k : {0, 2}) {
        double sum_sin = 0.0, sum_cos = 0.0;
        for (const Eigen::Vector3d &a : angles) {
            sum_sin += std::sin(a[k]);
            sum_cos += std::cos(a[k]);
        }
        const double centre = std::atan2(sum_sin, sum_cos);
        for (Eigen::Vector3d &a : angles)
            a[k] = centre + wrap_angle(a[k] - centre);
    }
    EulerLimit limit;
    limit.order = options.order;
    for (int k = 0; k < 3; ++k) {
        std::vector<double> values(n);
        for (std::size_t i = 0; i < n; ++i)
            values[i] = angles[i][k];
        if (options.method == EulerLimitOptions::Method::mean_std) {
            double mean = 0.0;
            for (double v : values)
                mean += v;
            mean /= static_cast<double>(n);
            double sum_sq = 0.0;
            for (double v : values)
                sum_sq += (v - mean) * (v - mean);
            const double std_dev = n > 1 ? std::sqrt(sum_sq / static_cast<double>(n - 1)) : 0.0;
            limit.lower_rad[k] = mean - options.k * std_dev;
            limit.upper_rad[k] = mean + options.k * std_dev;
        } else {
            std::sort(values.begin(), values.end());
            limit.lower_rad[k] = percentile_of_sorted(values, options.percentile);
            limit.upper_rad[k] = percentile_of_sorted(values, 100.0 - options.percentile);
        }
    }
    return limit;
}

// ---- Quaternion, Algorithm 1 -------------------------------------------------

Eigen::Vector3d QuaternionLimit::tangent(const Eigen::Quaterniond &q) const
{
    return log_map((mean.conjugate() * q.normalized()).normalized());
}

double QuaternionLimit::normalized_distance(const Eigen::Quaterniond &q) const
{
    const Eigen::Vector3d along = axes.transpose() * tangent(q); // coordinates on e_j
    double sum = 0.0;
    for (int j = 0; j < 3; ++j) {
        const double half_axis = k * sigma_rad[j];
        sum += (along[j] / half_axis) * (along[j] / half_axis);
    }
    return std::sqrt(sum);
}

bool QuaternionLimit::contains(const Eigen::Quaterniond &q, double tolerance) const
{
    return normalized_distance(q) <= 1.0 + tolerance;
}

Eigen::Quaterniond QuaternionLimit::clamp(const Eigen::Quaterniond &q) const
{
    const double distance = normalized_distance(q);
    if (distance <= 1.0)
        return q.normalized();
    // Radial projection: the point where the segment mean -> q (a ray in the
    // tangent space) crosses the ellipsoid. Not the closest surface point, but
    // it keeps the direction of the excursion and needs no iteration.
    return (mean * exp_map(tangent(q) / distance)).normalized();
}

QuaternionLimit learn_quaternion_limit(const std::vector<Eigen::Quaterniond> &series,
                                       const QuaternionLimitOptions &options)
{
    check_series(series, "learn_quaternion_limit");
    if (!std::isfinite(options.k) || options.k <= 0.0)
        throw MocapError("learn_quaternion_limit", 0,
                         "expected k finite and > 0, got " + std::to_string(options.k));
    if (!std::isfinite(options.sigma_floor_rad) || options.sigma_floor_rad <= 0.0)
        throw MocapError("learn_quaternion_limit", 0,
                         "expected sigma_floor_rad finite and > 0, got " +
                             std::to_string(options.sigma_floor_rad));
    QuaternionLimit limit;
    limit.k = options.k;
    // Algorithm 1, line 1: q_bar = mean(Q) (sign-robust, Markley et al. 2007).
    limit.mean = mean_rotation(series);
    // Lines 2-4: q_i* = log(q_bar^-1 q_i), as rotation vectors (angle * axis).
    // (The paper writes q_bar * q_i; the tangent space at q_bar needs the
    // inverse, so that q_i = q_bar gives 0.)
    // Line 5: SVD of the n x 3 matrix of the q_i*. Its right singular vectors
    // and singular values s_j are the eigenvectors and sqrt(n * eigenvalues) of
    // C = (1/n) sum q_i* q_i*^T, which is what is computed: sigma_j = s_j / sqrt(n),
    // the RMS spread about the mean rotation along e_j (not re-centred).
    Eigen::Matrix3d second_moment = Eigen::Matrix3d::Zero();
    for (const Eigen::Quaterniond &q : series) {
        const Eigen::Vector3d v = limit.tangent(q);
        second_moment += v * v.transpose();
    }
    second_moment /= static_cast<double>(series.size());
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver(second_moment);
    // Ascending eigenvalues -> descending sigma.
    for (int j = 0; j < 3; ++j) {
        Eigen::Vector3d axis = solver.eigenvectors().col(2 - j);
        // A fixed sign for reproducible output: largest component positive.
        Eigen::Index largest = 0;
        axis.cwiseAbs().maxCoeff(&largest);
        if (axis[largest] < 0.0)
            axis = -axis;
        limit.axes.col(j) = axis;
        const double variance = std::max(0.0, solver.eigenvalues()[2 - j]);
        limit.sigma_rad[j] = std::max(std::sqrt(variance), options.sigma_floor_rad);
    }
    limit.axes.col(2) = limit.axes.col(0).cross(limit.axes.col(1)); // right-handed
    return limit;
}

// ---- per joint, JSON, table ---------------------------------------------------

std::vector<Eigen::Quaterniond> joint_series(const Motion &motion, int joint)
{
    std::vector<Eigen::Quaterniond> series;
    series.reserve(motion.local_rotation.size());
    for (std::size_t f = 0; f < motion.local_rotation.size(); ++f) {
        const auto &frame = motion.local_rotation[f];
        if (joint < 0 || joint >= static_cast<int>(frame.size()))
            throw MocapError("joint_series", 0,
                             "expected a joint index in [0, " + std::to_string(frame.size()) +
                                 "), got " + std::to_string(joint) + " at frame " +
                                 std::to_string(f));
        series.push_back(frame[static_cast<std::size_t>(joint)]);
    }
    return series;
}

std::vector<JointLimit> learn_limits(const std::vector<std::string> &names,
                                     const std::vector<std::vector<Eigen::Quaterniond>> &series,
                                     const LimitOptions &options)
{
    if (names.size() != series.size())
        throw MocapError("learn_limits", 0,
                         "expected one name per series, got " + std::to_string(names.size()) +
                             " names and " + std::to_string(series.size()) + " series");
    std::vector<JointLimit> limits;
    limits.reserve(names.size());
    for (std::size_t i = 0; i < names.size(); ++i) {
        if (series[i].empty())
            throw MocapError("learn_limits", 0,
                             "expected rotations for joint " + names[i] + ", got none");
        JointLimit limit;
        limit.name = names[i];
        limit.samples = static_cast<int>(series[i].size());
        limit.euler = learn_euler_limit(series[i], options.euler);
        limit.quaternion = learn_quaternion_limit(series[i], options.quaternion);
        limits.push_back(limit);
    }
    return limits;
}

std::vector<JointLimit> learn_limits(const Skeleton &skeleton, const Motion &motion,
                                     const LimitOptions &options)
{
    std::vector<std::string> names;
    std::vector<std::vector<Eigen::Quaterniond>> series;
    for (std::size_t j = 0; j < skeleton.joints.size(); ++j) {
        if (skeleton.joints[j].end_site)
            continue;
        names.push_back(skeleton.joints[j].name);
        series.push_back(joint_series(motion, static_cast<int>(j)));
    }
    return learn_limits(names, series, options);
}

nlohmann::json to_json(const EulerLimit &limit)
{
    return {{"order", to_string(limit.order)},
            {"lower_rad", vector_json(limit.lower_rad)},
            {"upper_rad", vector_json(limit.upper_rad)},
            {"lower_deg", vector_json(limit.lower_rad * kRadToDeg)},
            {"upper_deg", vector_json(limit.upper_rad * kRadToDeg)}};
}

nlohmann::json to_json(const QuaternionLimit &limit)
{
    nlohmann::json axes = nlohmann::json::array();
    for (int j = 0; j < 3; ++j)
        axes.push_back(vector_json(limit.axes.col(j)));
    return {{"mean_wxyz", {limit.mean.w(), limit.mean.x(), limit.mean.y(), limit.mean.z()}},
            {"axes", axes},
            {"sigma_rad", vector_json(limit.sigma_rad)},
            {"k", limit.k},
            {"half_axes_deg", vector_json(limit.k * limit.sigma_rad * kRadToDeg)}};
}

nlohmann::json to_json(const JointLimit &limit)
{
    return {{"name", limit.name},
            {"samples", limit.samples},
            {"euler", to_json(limit.euler)},
            {"quaternion", to_json(limit.quaternion)}};
}

EulerLimit euler_limit_from_json(const nlohmann::json &j)
{
    if (!j.is_object() || !j.contains("order") || !j["order"].is_string())
        throw MocapError("joint limit JSON", 0, "expected an object with \"order\" (string)");
    EulerLimit limit;
    limit.order = euler_order_from_string(j["order"].get<std::string>());
    limit.lower_rad = vector_from_json(j, "lower_rad");
    limit.upper_rad = vector_from_json(j, "upper_rad");
    for (int k = 0; k < 3; ++k)
        if (limit.lower_rad[k] > limit.upper_rad[k])
            throw MocapError("joint limit JSON", 0,
                             "expected lower_rad <= upper_rad, got axis " + std::to_string(k) +
                                 " reversed");
    return limit;
}

QuaternionLimit quaternion_limit_from_json(const nlohmann::json &j)
{
    if (!j.is_object() || !j.contains("mean_wxyz") || !j["mean_wxyz"].is_array() ||
        j["mean_wxyz"].size() != 4 || !j.contains("axes") || !j["axes"].is_array() ||
        j["axes"].size() != 3 || !j.contains("k") || !j["k"].is_number())
        throw MocapError("joint limit JSON", 0,
                         "expected an object with mean_wxyz[4], axes[3][3], sigma_rad[3], k");
    QuaternionLimit limit;
    double m[4];
    for (std::size_t i = 0; i < 4; ++i) {
        if (!j["mean_wxyz"][i].is_number())
            throw MocapError("joint limit JSON", 0, "expected numbers in mean_wxyz");
        m[i] = j["mean_wxyz"][i].get<double>();
    }
    limit.mean = Eigen::Quaterniond(m[0], m[1], m[2], m[3]);
    const double norm = limit.mean.norm();
    if (!std::isfinite(norm) || norm < 1e-9)
        throw MocapError("joint limit JSON", 0, "expected a non-zero finite mean_wxyz");
    limit.mean.normalize();
    for (int a = 0; a < 3; ++a) {
        nlohmann::json holder = {{"axis", j["axes"][static_cast<std::size_t>(a)]}};
        limit.axes.col(a) = vector_from_json(holder, "axis").normalized();
    }
    if (std::fabs(limit.axes.determinant() - 1.0) > 1e-6)
        throw MocapError("joint limit JSON", 0, "expected orthonormal right-handed axes");
    limit.sigma_rad = vector_from_json(j, "sigma_rad");
    limit.k = j["k"].get<double>();
    if (!(limit.sigma_rad.minCoeff() > 0.0) || !std::isfinite(limit.k) || !(limit.k > 0.0))
        throw MocapError("joint limit JSON", 0, "expected sigma_rad > 0 and k > 0");
    return limit;
}

nlohmann::json limits_report(const std::vector<JointLimit> &limits, const LimitOptions &options)
{
    nlohmann::json joints = nlohmann::json::array();
    for (const JointLimit &limit : limits)
        joints.push_back(to_json(limit));
    return {{"conventions",
             {{"euler", "intrinsic, R = R_a0 R_a1 R_a2 for order a0a1a2; angles in rad/deg"},
              {"quaternion", "tangent v = log(mean^-1 q) as angle*axis (rad); inside when "
                             "sum_j (v.e_j / (k sigma_j))^2 <= 1; axes listed as e_0, e_1, e_2"}}},
            {"options",
             {{"euler",
               {{"order", to_string(options.euler.order)},
                {"method", method_name(options.euler.method)},
                {"k", options.euler.k},
                {"percentile", options.euler.percentile}}},
              {"quaternion",
               {{"k", options.quaternion.k},
                {"sigma_floor_rad", options.quaternion.sigma_floor_rad}}}}},
            {"joints", joints}};
}

nlohmann::json limits_report(const std::vector<std::string> &names,
                             const std::vector<std::vector<Eigen::Quaterniond>> &series,
                             const LimitOptions &options)
{
    return limits_report(learn_limits(names, series, options), options);
}

void print_limits(std::ostream &out, const std::vector<JointLimit> &limits)
{
    std::size_t width = 5;
    for (const JointLimit &limit : limits)
        width = std::max(width, limit.name.size());
    std::ostringstream text;
    text << std::fixed << std::setprecision(1);
    text << std::left << std::setw(static_cast<int>(width)) << "joint" << std::right << std::setw(7)
         << "n"
         << "  euler  " << std::setw(22) << "a0 lower..upper (deg)" << std::setw(22)
         << "a1 lower..upper" << std::setw(22) << "a2 lower..upper"
         << "   quat k*sigma (deg)\n";
    for (const JointLimit &limit : limits) {
        text << std::left << std::setw(static_cast<int>(width)) << limit.name << std::right
             << std::setw(7) << limit.samples << "  " << std::setw(5)
             << to_string(limit.euler.order) << "  ";
        for (int k = 0; k < 3; ++k) {
            std::ostringstream range;
            range << std::fixed << std::setprecision(1) << limit.euler.lower_rad[k] * kRadToDeg
                  << ".." << limit.euler.upper_rad[k] * kRadToDeg;
            text << std::setw(22) << range.str();
        }
        text << "  ";
        for (int j = 0; j < 3; ++j)
            text << std::setw(7) << limit.quaternion.k * limit.quaternion.sigma_rad[j] * kRadToDeg;
        text << "\n";
    }
    out << text.str();
}

} // namespace ictus
