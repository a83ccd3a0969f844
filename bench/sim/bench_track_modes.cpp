// bench_sim_track_modes: the whole tracking loop, joint space (eq. 1) vs
// Cartesian (Algorithm 2: two IK solves per arm and step, eq. 2, then eq. 1),
// on the CMU drumming clip at 1 kHz on one core: microseconds per step, the
// IK's share, and the real-time factor (target: >= 20x for the hybrid mode).
// usage: bench_sim_track_modes [BVH] [seconds] [runs]
#include "ictus/mocap/bvh.hpp"
#include "ictus/character/character_limits.hpp"
#include "ictus/perform/track.hpp"

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

using namespace ictus;

int main(int argc, char **argv)
{
    const char *env = std::getenv("ICTUS_DATA_DIR");
    std::string path = std::string(env ? env : ICTUS_DATA_DIR_DEFAULT) + "/cmu/80_13.bvh";
    if (argc > 1 && *argv[1])
        path = argv[1];
    const double seconds = argc > 2 ? std::atof(argv[2]) : 30.0;
    const int runs = argc > 3 ? std::max(1, std::atoi(argv[3])) : 3;
    BvhOptions bo;
    bo.scale = ictus::kCmuBvhScale_m;
    bo.skip_frames = 1;
    BvhFile bvh;
    try {
        bvh = read_bvh(path, bo);
    } catch (const std::exception &e) {
        std::fprintf(stderr, "bench_sim_track_modes: %s\n", e.what());
        return 1;
    }
    const CharacterModel model = CharacterModel::from_skeleton(bvh.skeleton);
    // `ictusd track`'s clean-up and default limits (k = 3), as scripts/figure4.sh
    // and the Cartesian test.
    const ReferenceMotion reference(model, bvh.motion, track_reference_filter());
    const CharacterLimits limits(model, reference, CharacterLimitOptions{});
    std::printf("%s, %.0f simulated s per run, best of %d runs, 1 kHz, one core\n", path.c_str(),
                seconds, runs);
    std::printf("mode        us/step  ik us/step  ik it/solve  real time  tip rms L/R mm\n");
    // joint; cartesian at the defaults (Algorithm 2 from the simulated state,
    // posture task, 2 iterations per solve); the capture-seeded variant
    // (--ik-start kinematic, solved to convergence).
    for (int variant = 0; variant < 3; ++variant) {
        const TrackMode mode = variant == 0 ? TrackMode::joint : TrackMode::cartesian;
        TrackOptions o;
        o.mode = mode;
        o.duration_s = seconds;
        if (variant == 2) {
            o.cartesian.start_from_simulated = false;
            o.cartesian.posture_weight = 0.0;
            o.cartesian.feedback_iterations = 0;
            o.cartesian.kinematic_iterations = 0;
            o.cartesian.correction_limit_m = 0.1;
        }
        TrackSummary best;
        for (int r = 0; r < runs; ++r) {
            const TrackSummary s = track_joint_space(model, reference, o, limits.refs());
            if (r == 0 || s.wall_time_s < best.wall_time_s)
                best = s;
        }
        std::printf("%-10s  %7.1f  %10.1f  %11.2f  %8.1fx  %.2f / %.2f\n",
                    variant == 2 ? "cart-seed" : to_string(mode),
                    1e6 * best.wall_time_s / std::max(1L, best.steps), best.ik_us_per_step,
                    best.ik_mean_iterations, best.realtime_factor, best.tip_rms_mm[0],
                    best.tip_rms_mm[1]);
    }
    return 0;
}
