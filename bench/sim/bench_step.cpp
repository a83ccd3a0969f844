// bench_sim_step: microseconds per physics step of the full character (57 DoF,
// 19 PD motors of eq. 1, quaternion limits with stops, stick-drum collision)
// at 1 kHz while tracking the CMU drumming clip, with a breakdown (targets,
// control, collide, solve, check) and the real-time factor on one core.
// usage: bench_sim_step [BVH] [seconds] [iterations] [drum raise above the lowest tips, m]
#include "ictus/base/rotation.hpp"
#include "ictus/mocap/bvh.hpp"
#include "ictus/mocap/joint_limits.hpp"
#include "ictus/sim/scene.hpp"
#include "ictus/perform/track.hpp"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

using namespace ictus;

int main(int argc, char **argv)
{
    const char *env = std::getenv("ICTUS_DATA_DIR");
    std::string path = std::string(env ? env : ICTUS_DATA_DIR_DEFAULT) + "/cmu/80_13.bvh";
    if (argc > 1)
        path = argv[1];
    const double seconds = argc > 2 ? std::atof(argv[2]) : 20.0;
    const int iterations = argc > 3 ? std::atoi(argv[3]) : 15;
    const double drum_raise_m = argc > 4 ? std::atof(argv[4]) : 0.05;
    BvhOptions bo;
    bo.scale = ictus::kCmuBvhScale_m;
    bo.skip_frames = 1;
    BvhFile bvh;
    try {
        bvh = read_bvh(path, bo);
    } catch (const std::exception &e) {
        std::fprintf(stderr, "bench_sim_step: %s\n", e.what());
        return 1;
    }
    const CharacterModel model = CharacterModel::from_skeleton(bvh.skeleton);
    const ReferenceMotion reference(model, bvh.motion, ReferenceFilter{});
    std::vector<std::string> names;
    std::vector<std::vector<Eigen::Quaterniond>> series(CharacterModel::kJoints);
    for (int j = 0; j < CharacterModel::kJoints; ++j) {
        names.push_back(model.joint_name(j));
        for (int f = 0; f < reference.frames(); ++f)
            series[j].push_back(reference.frame(f).local[j]);
    }
    const std::vector<JointLimit> limits = learn_limits(names, series);
    std::vector<JointLimitRef> refs;
    for (const JointLimit &l : limits)
        refs.push_back(JointLimitRef::to(l.quaternion));

    SceneOptions so;
    so.quickstep_iterations = iterations;
    // The membrane 5 cm above the lowest reference tips, so that the sticks
    // really strike it and the contact rows are part of the cost.
    so.drum.center_m = auto_drum_center(model, reference) + Eigen::Vector3d(0, drum_raise_m, 0);
    const CharacterPose initial = reference.frame(0);
    Scene scene(model, so, initial, default_gains(model, initial, GainOptions{}));
    scene.set_joint_limits(refs);

    const long steps = static_cast<long>(seconds / so.step_s);
    std::vector<double> total(steps), control(steps), collide(steps), solve(steps), check(steps),
        targets(steps);
    CharacterPose pose;
    std::vector<Eigen::Quaterniond> target(CharacterModel::kJoints), previous = initial.local;
    std::vector<Eigen::Vector3d> rate(CharacterModel::kJoints);
    using clock = std::chrono::steady_clock;
    const auto start = clock::now();
    for (long n = 0; n < steps; ++n) {
        const auto t0 = clock::now();
        reference.sample((n + 1) * so.step_s, pose);
        for (int j = 0; j < CharacterModel::kJoints; ++j) {
            target[j] = pose.local[j];
            rate[j] = log_map(target[j] * previous[j].conjugate()) / so.step_s;
        }
        previous = target;
        scene.set_joint_targets(target, rate);
        const auto t1 = clock::now();
        StepTiming timing;
        scene.step(&timing);
        const auto t2 = clock::now();
        targets[n] = std::chrono::duration<double>(t1 - t0).count();
        total[n] = std::chrono::duration<double>(t2 - t0).count();
        control[n] = timing.control_s;
        collide[n] = timing.collide_s;
        solve[n] = timing.solve_s;
        check[n] = timing.check_s;
    }
    const double wall = std::chrono::duration<double>(clock::now() - start).count();
    auto mean_us = [](const std::vector<double> &v) {
        double s = 0;
        for (double x : v)
            s += x;
        return 1e6 * s / v.size();
    };
    auto pct_us = [](std::vector<double> v, double p) {
        std::sort(v.begin(), v.end());
        return 1e6 * v[static_cast<size_t>(p * (v.size() - 1))];
    };
    std::printf("ictusd physics step: 20 bodies, 19 ball joints + AMotors (57 DoF), "
                "quaternion limits, stick-drum collision, step %.3f ms, QuickStep %d it.\n",
                so.step_s * 1e3, iterations);
    std::printf("steps %ld (%.1f s simulated), divergences %d, steps with contact %ld (%.1f %%)\n",
                steps, steps * so.step_s, scene.divergences(), scene.contact_steps(),
                100.0 * scene.contact_steps() / steps);
    std::printf("per step (us): mean %.1f  median %.1f  p99 %.1f\n", mean_us(total),
                pct_us(total, 0.5), pct_us(total, 0.99));
    std::printf(
        "  targets (sample+rate) %.2f  control %.2f  collide %.2f  solve %.2f  check %.2f\n",
        mean_us(targets), mean_us(control), mean_us(collide), mean_us(solve), mean_us(check));
    std::printf("real-time factor (1 core): %.1fx\n", steps * so.step_s / wall);
    return scene.divergences() == 0 ? 0 : 3;
}
