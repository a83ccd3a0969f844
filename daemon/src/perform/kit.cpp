// The built-in kits and their checks (kit.hpp, docs/perform.md "A kit").
#include "ictus/perform/kit.hpp"

#include "ictus/perform/perform_error.hpp"
#include "membrane.h"
#include "membrane_presets.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

namespace ictus
{

namespace
{

constexpr double kInch_m = 0.0254;
// The full kit's rack toms stand this much higher than the standard's, and
// its floor tom this far right of the snare and behind it, beside the right knee (m).
constexpr double kFullRackRaise_m = 0.13;
constexpr double kFullFloorRight_m = 0.56, kFullFloorForward_m = -0.20;
// Its ride nearer the right shoulder, where the floor tom's move leaves room
// (2 cm clear of tom2 and of the floor tom in plan; m, the anchor's frame).
const Eigen::Vector3d kFullRide_m{0.62, 0.22, 0.28};

// A drum of the preset `preset`, its diameter in inches (the preset's radius
// when 0) and shell depth in inches, at `place` (right, up, forward; m).
KitDrum drum(const char *name, const char *preset, double diameter_in, double depth_in,
             const Eigen::Vector3d &place, int midi_note)
{
    const membrane_preset *p = membrane_preset_find(preset);
    if (!p)
        throw PerformError(std::string("kit: no membrane preset '") + preset + "'");
    KitDrum d;
    d.name = name;
    d.preset = preset;
    d.place_m = place;
    d.radius_m = diameter_in > 0.0 ? 0.5 * diameter_in * kInch_m : p->radius_m;
    d.tension_n_per_m = p->tension_n_per_m;
    d.density_kg_per_m2 = p->density_kg_per_m2;
    d.bending_n_m = p->plate ? p->bending_n_m : 0.0;
    d.shell_depth_m = depth_in * kInch_m;
    d.midi_note = midi_note;
    return d;
}

// A right-handed four-piece (docs/perform.md, "A kit", gives the sources):
// the snare where the one drum goes; the rack toms beyond it, a little
// higher, small to the left and large to the right; the floor tom to the
// snare's right, a little lower. Sizes: 14x5.5 snare, 10x8 and 12x9 rack
// toms, 16x16 floor tom. MIDI: General MIDI's snare and toms (38, 48, 47, 43).
std::vector<KitDrum> standard_drums()
{
    return {drum("snare", "snare", 14.0, 5.5, {0.0, 0.0, 0.0}, 38),
            drum("tom1", "tom", 10.0, 8.0, {-0.15, 0.10, 0.30}, 48),
            drum("tom2", "tom", 12.0, 9.0, {0.19, 0.08, 0.32}, 47),
            drum("floor", "floor-tom", 16.0, 16.0, {0.40, 0.0, -0.05}, 43)};
}

// The cymbals of "standard-cymbals" (docs/kit.md gives the sources): an
// 18-inch crash to the left beyond the small tom, a 20-inch ride to the
// right beyond the large one, both higher than the toms, and a 14-inch
// hi-hat where a right-handed drummer's stands: left of the snare, a little
// higher, for the left hand and the right hand crossing over. Each is clear
// of every head in plan (kKitMinGap_m); the crash stands a little further
// left and forward than it would without the hi-hat, to clear it. General
// MIDI's Crash Cymbal 1 (49), Ride Cymbal 1 (51) and Closed Hi-Hat (42).
// Each is a disc 1 cm thick (its stand and the hi-hat's bottom plate are
// not in the scene).
std::vector<KitDrum> cymbals()
{
    constexpr double kDisc_in = 0.4; // 1 cm
    return {drum("crash", "crash", 0.0, kDisc_in, {-0.64, 0.30, 0.36}, 49),
            drum("ride", "ride", 0.0, kDisc_in, {0.66, 0.22, 0.38}, 51),
            drum("hihat", "hihat", 14.0, kDisc_in, {-0.42, 0.26, -0.02}, 42)};
}

// The kick of "full": a 22x18 bass drum on the floor before the right foot,
// its batter upright facing the performer, its centre half its diameter
// (0.28 m) above the floor, the batter 0.27 m ahead of the right ankle: the
// pedal's footboard (about 0.28 m, heel plate to axle) under the foot, its
// heel behind the ankle. A foot piece's place is from the right ankle over
// the floor (docs/kit.md, "The kick"). General MIDI's Bass Drum 1 (36).
KitDrum kick()
{
    KitDrum d = drum("kick", "kick", 22.0, 18.0, {0.0, 11.0 * kInch_m, 0.27}, 36);
    d.foot = true;
    return d;
}

} // namespace

std::string kit_names()
{
    return "standard, standard-cymbals, full, standard-timpani, timpani";
}

int kit_hand_pieces(const Kit &kit)
{
    int n = 0;
    for (const KitDrum &d : kit.drums)
        n += d.foot ? 0 : 1;
    return n;
}

int kit_foot_piece(const Kit &kit)
{
    for (size_t i = 0; i < kit.drums.size(); ++i)
        if (kit.drums[i].foot)
            return static_cast<int>(i);
    return -1;
}

Kit kit_named(const std::string &name)
{
    Kit kit;
    kit.name = name;
    if (name == "standard") {
        kit.drums = standard_drums();
    } else if (name == "standard-cymbals") {
        kit.drums = standard_drums();
        for (const KitDrum &c : cymbals())
            kit.drums.push_back(c);
    } else if (name == "full") {
        // Seated, the thighs run where the standing kit's floor tom stands
        // and the kick lies under the rack toms: the floor tom beside the
        // right knee, the rack toms above the kick, and the ride where the
        // floor tom leaves room, nearer the right hand (docs/kit.md, "The
        // throne").
        kit.drums = standard_drums();
        kit.drums[1].place_m.y() += kFullRackRaise_m;
        kit.drums[2].place_m.y() += kFullRackRaise_m;
        kit.drums[3].place_m.x() = kFullFloorRight_m;
        kit.drums[3].place_m.z() = kFullFloorForward_m;
        for (const KitDrum &c : cymbals())
            kit.drums.push_back(c);
        kit.drums[5].place_m = kFullRide_m;
        kit.drums.push_back(kick());
    } else if (name == "standard-timpani") {
        // A 26-inch timpani (its kettle 0.6 m deep) where a hi-hat would
        // stand, left of the snare, its head level with the snare's. No
        // General MIDI drum sounds a timpani: its note is its pitch, A2 (45;
        // docs/midi.md).
        kit.drums = standard_drums();
        kit.drums.push_back(drum("timpani", "timpani", 0.0, 24.0, {-0.57, 0.0, 0.06}, 45));
    } else if (name == "timpani") {
        // Two 26-inch timpani side by side, heads level, the player behind
        // and between them: the kit's anchor (where the one drum goes) midway.
        kit.drums = {drum("timpani1", "timpani", 0.0, 24.0, {-0.36, 0.0, 0.05}, 45),
                     drum("timpani2", "timpani", 0.0, 24.0, {0.36, 0.0, 0.05}, 45)};
    } else {
        throw PerformError("unknown kit '" + name + "' (valid: " + kit_names() + ")");
    }
    validate_kit(kit);
    return kit;
}

double kit_min_gap_m(const Kit &kit)
{
    double gap = std::numeric_limits<double>::infinity();
    for (size_t i = 0; i < kit.drums.size(); ++i)
        for (size_t j = i + 1; j < kit.drums.size(); ++j) {
            const KitDrum &a = kit.drums[i], &b = kit.drums[j];
            if (a.foot || b.foot) // on the floor, under the others: not in the sticks' way
                continue;
            const double d =
                std::hypot(a.place_m.x() - b.place_m.x(), a.place_m.z() - b.place_m.z());
            gap = std::min(gap, d - a.radius_m - b.radius_m);
        }
    return gap;
}

double kit_drum_pan(const KitDrum &drum)
{
    return std::clamp(-drum.place_m.x() / 0.8, -0.6, 0.6);
}

bool kit_drum_has_pedal(const KitDrum &drum)
{
    const membrane_preset *p = membrane_preset_find(drum.preset.c_str());
    return p && p->plate && p->edge_damp_n_s_per_m2 > 0.0;
}

int kit_drum_index(const Kit &kit, const std::string &name)
{
    for (size_t i = 0; i < kit.drums.size(); ++i)
        if (kit.drums[i].name == name)
            return static_cast<int>(i);
    return -1;
}

void validate_kit(const Kit &kit)
{
    const std::string what = "kit '" + kit.name + "': ";
    if (kit.drums.empty() || kit.drums.size() > static_cast<size_t>(kMaxDrums))
        throw PerformError(what + "expected 1.." + std::to_string(kMaxDrums) + " drums, got " +
                           std::to_string(kit.drums.size()));
    for (size_t i = 0; i < kit.drums.size(); ++i) {
        const KitDrum &d = kit.drums[i];
        const std::string who = what + "drum '" + d.name + "': ";
        bool name_ok = !d.name.empty() && d.name.size() <= 32;
        for (char c : d.name)
            name_ok = name_ok &&
                      ((c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '_' || c == '-');
        if (!name_ok)
            throw PerformError(what + "drum name '" + d.name +
                               "': expected lower-case letters, digits, '_' and '-' (1..32)");
        if (kit_drum_index(kit, d.name) != static_cast<int>(i))
            throw PerformError(who + "the name is given twice");
        const membrane_preset *preset = membrane_preset_find(d.preset.c_str());
        if (!preset)
            throw PerformError(who + "unknown preset '" + d.preset +
                               "' (the presets: " + membrane_preset_names() + ")");
        if (preset->plate != (d.cymbal() ? 1 : 0))
            throw PerformError(who + "preset '" + d.preset + "' is " +
                               (preset->plate ? "a cymbal, and the drum has no bending stiffness"
                                              : "a drum, and the drum has a bending stiffness"));
        if (d.foot && (d.cymbal() || i == 0))
            throw PerformError(who + "a foot's piece is a drum and not the kit's first");
        if (!d.foot && i > 0 && kit.drums[i - 1].foot)
            throw PerformError(who + "the hands' pieces come before the foot's");
        if (i == 0 && d.cymbal())
            throw PerformError(who +
                               "the first drum must be a drum, not a cymbal (the drum "
                               "presets: " +
                               membrane_preset_drum_names() + ")");
        if (!(d.radius_m >= 0.05 && d.radius_m <= 1.0))
            throw PerformError(who + "radius must be 0.05..1 m");
        if (d.cymbal() ? !(d.bending_n_m <= 1e4 && d.tension_n_per_m == 0.0)
                       : !(d.tension_n_per_m >= 10.0 && d.tension_n_per_m <= 1e5))
            throw PerformError(who + (d.cymbal() ? "a cymbal's bending stiffness must be "
                                                   "0..1e4 N m, and it has no tension"
                                                 : "tension must be 10..1e5 N/m"));
        if (!(d.density_kg_per_m2 >= MEMBRANE_DENSITY_MIN && d.density_kg_per_m2 <= MEMBRANE_DENSITY_MAX))
            throw PerformError(who + "density must be 0.01..20 kg/m^2");
        if (!(d.shell_depth_m >= 0.01 && d.shell_depth_m <= 1.5))
            throw PerformError(who + "shell depth must be 0.01..1.5 m");
        if (!(d.place_m.allFinite() && d.place_m.cwiseAbs().maxCoeff() <= 2.0))
            throw PerformError(who + "place must be within 2 m of the first drum");
        if (d.midi_note < 0 || d.midi_note > 127)
            throw PerformError(who + "MIDI note must be 0..127");
    }
    const double gap = kit_min_gap_m(kit);
    if (gap < kKitMinGap_m) {
        std::ostringstream m;
        m << what << "two shells are " << gap * 100.0 << " cm apart in plan (at least "
          << kKitMinGap_m * 100.0 << " cm: a stick must reach each head from above)";
        throw PerformError(m.str());
    }
}

std::vector<DrumParams> place_kit(const Kit &kit, const DrumParams &base,
                                  const Eigen::Vector3d &anchor_m,
                                  const Eigen::Vector3d &right, const Eigen::Vector3d &up,
                                  const Eigen::Vector3d &forward)
{
    std::vector<DrumParams> out;
    for (const KitDrum &d : kit.drums) {
        if (d.foot)
            continue;
        DrumParams p = base;
        p.center_m =
            anchor_m + d.place_m.x() * right + d.place_m.y() * up + d.place_m.z() * forward;
        p.radius_m = d.radius_m;
        p.tension_n_per_m = d.tension_n_per_m;
        p.plate_bending_n_m = d.bending_n_m;
        // Mylar, as membrane~'s head: the film as thick as the density says,
        // for its stretching under the stick (DrumParams::stretch_n_per_m3).
        p.head_thickness_m = d.density_kg_per_m2 / MEMBRANE_MYLAR_RHO;
        p.shell_depth_m = d.shell_depth_m;
        out.push_back(p);
    }
    return out;
}

} // namespace ictus
