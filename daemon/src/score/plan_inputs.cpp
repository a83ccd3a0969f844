// plan_inputs.cpp -- the performer frame and the plan options checked before
// a plan is made (docs/score.md, "From score to motion").
#include "plan_inputs.hpp"

#include <cmath>
#include <sstream>
#include <stdexcept>
#include <string>

namespace ictus
{
namespace score_detail
{

namespace
{

void check_unit(const Eigen::Vector3d &v, const char *name)
{
    if (!v.allFinite() || std::abs(v.norm() - 1.0) > 1e-6)
        throw std::invalid_argument(std::string("PerformerFrame: ") + name +
                                    " must be a unit vector");
}

// A kit's drums in the frame and the planner's margins for it.
void validate_kit(const PerformerFrame &f, const PlanOptions &o)
{
    for (const PerformerFrame::Drum &d : f.drums)
        if (!d.membrane_center_m.allFinite() || !(d.membrane_radius_m > 0.0) ||
            !std::isfinite(d.membrane_radius_m))
            throw std::invalid_argument("PerformerFrame: kit drum '" + d.name +
                                        "' needs a finite centre and a radius > 0");
    if (!(o.kit_clearance_m >= 0.0 && o.kit_clearance_m <= 0.5 && o.kit_margin_m >= 0.0 &&
          o.kit_margin_m <= 0.5))
        throw std::invalid_argument(
            "PlanOptions: kit_clearance_m and kit_margin_m must be 0..0.5 m");
}

} // namespace

void validate_plan_inputs(const PerformerFrame &f, const PlanOptions &o)
{
    check_unit(f.right, "right");
    check_unit(f.up, "up");
    check_unit(f.forward, "forward");
    if (std::abs(f.right.dot(f.up)) > 1e-6 || std::abs(f.up.dot(f.forward)) > 1e-6 ||
        std::abs(f.forward.dot(f.right)) > 1e-6)
        throw std::invalid_argument("PerformerFrame: right, up and forward must be orthogonal");
    if (!(f.membrane_radius_m > 0.0) || !std::isfinite(f.membrane_radius_m))
        throw std::invalid_argument("PerformerFrame: membrane_radius_m must be > 0");
    if (!f.membrane_center_m.allFinite() || !f.rest_tip_m[0].allFinite() ||
        !f.rest_tip_m[1].allFinite())
        throw std::invalid_argument("PerformerFrame: positions must be finite");
    validate_kit(f, o);
    auto bad = [](const char *what, double v) {
        std::ostringstream s;
        s << "PlanOptions: " << what << ", got " << v;
        throw std::invalid_argument(s.str());
    };
    if (!(o.lead_in_s >= 0.2 && o.lead_in_s <= 60.0))
        bad("lead_in_s must be 0.2..60 s", o.lead_in_s);
    if (!(o.tail_s >= 0.0 && o.tail_s <= 60.0))
        bad("tail_s must be 0..60 s", o.tail_s);
    if (!(o.humanize <= kMaxHumanize)) // < 0: the score's
        bad("humanize must be 0..4", o.humanize);
    if (!(o.rate_hz >= 50.0 && o.rate_hz <= 20000.0))
        bad("rate_hz must be 50..20000", o.rate_hz);
    if (!(std::abs(o.strike_depth_m) <= 0.1))
        bad("strike_depth_m must be within +-0.1 m", o.strike_depth_m);
    if (!(o.strike_aim_s >= 0.0 && o.strike_aim_s <= 0.01))
        bad("strike_aim_s must be within 0..0.01 s", o.strike_aim_s);
    if (!(o.strike_aim_from_mps >= 0.0 && o.strike_aim_from_mps <= 20.0))
        bad("strike_aim_from_mps must be within 0..20 m/s", o.strike_aim_from_mps);
    if (!(o.strike_aim_max_m >= 0.0 && o.strike_aim_max_m <= 0.05))
        bad("strike_aim_max_m must be within 0..0.05 m", o.strike_aim_max_m);
    if (!(o.contact_lead_m >= 0.0 && o.contact_lead_m <= 0.01))
        bad("contact_lead_m must be within 0..0.01 m", o.contact_lead_m);
    if (!(o.blend_margin > 0.0 && o.blend_margin < 0.5))
        bad("blend_margin must be in (0, 0.5)", o.blend_margin);
    if (!(o.max_turn_rate_rad_s > 0.0 && o.max_turn_rate_rad_s <= 1000.0))
        bad("max_turn_rate_rad_s must be in (0, 1000]", o.max_turn_rate_rad_s);
    if (!(o.move_margin_after >= 0.0 && o.move_margin_before >= 0.0 &&
          o.move_margin_after + o.move_margin_before < 0.9))
        bad("move margins must be >= 0 and leave > 10 % of the gap",
            o.move_margin_after + o.move_margin_before);
    if (!(o.idle_return_s > 0.0) || !std::isfinite(o.idle_return_s))
        bad("idle_return_s must be > 0", o.idle_return_s);
    if (!(o.return_time_s > 0.0 && o.return_time_s <= 10.0))
        bad("return_time_s must be in (0, 10] s", o.return_time_s);
    if (!(o.min_stroke_interval_s > 0.0 && o.min_stroke_interval_s <= 10.0))
        bad("min_stroke_interval_s must be in (0, 10] s", o.min_stroke_interval_s);
    if (!(o.min_foot_interval_s > 0.0 && o.min_foot_interval_s <= 10.0))
        bad("min_foot_interval_s must be in (0, 10] s", o.min_foot_interval_s);
    if (!(o.min_chick_interval_s > 0.0 && o.min_chick_interval_s <= 10.0))
        bad("min_chick_interval_s must be in (0, 10] s", o.min_chick_interval_s);
    if (!(o.max_duration_s > 0.0) || !std::isfinite(o.max_duration_s))
        bad("max_duration_s must be > 0", o.max_duration_s);
}

} // namespace score_detail
} // namespace ictus
