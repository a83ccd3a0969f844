// kit.hpp -- several drums in the scene (docs/perform.md, "A kit"): each with
// a name (the score's `drum NAME`, `on NAME`), a head and sound (a membrane
// preset, externals/core/membrane_presets.h), a place before the performer,
// its shell and its General MIDI note. The drums are placed from the kit's
// anchor (where the one drum goes) in the performer's frame; the first is
// the scene's drum 0.
#pragma once

#include "ictus/sim/scene.hpp"

#include <Eigen/Core>
#include <string>
#include <vector>

namespace ictus
{

struct KitDrum {
    std::string name;   // lower case letters, digits, '_' and '-'
    std::string preset; // membrane preset: the head (radius, tension) and the sound
    // The membrane's centre from the kit's anchor (where the one drum goes),
    // in the performer's frame: x to the performer's right, y up, z forward (m).
    Eigen::Vector3d place_m = Eigen::Vector3d::Zero();
    double radius_m = 0.1778;
    double tension_n_per_m = 3603.0;
    double density_kg_per_m2 = 0.345; // the head's areal density (its film's thickness)
    double shell_depth_m = 0.14;
    int midi_note = 38; // General MIDI drum map (docs/midi.md)
    // A cymbal (a plate preset, docs/plates.md): its bending stiffness D (N m),
    // and no tension (0); 0 for a drum. In the scene it is a disc as thick as
    // shell_depth_m, its top face the plate (docs/kit.md, "Cymbals").
    double bending_n_m = 0.0;
    bool cymbal() const { return bending_n_m > 0.0; }
    // Played by the right foot on a pedal (the kick, docs/pedal.md): its head
    // stands upright facing the performer, place_m is the head's centre from
    // the right ankle over the floor (not from the anchor), and it is not in
    // the sticks' scene (the sticks play above it). A kit's foot pieces come
    // after every piece the hands play.
    bool foot = false;
};

struct Kit {
    std::string name; // "" : no kit (the one drum)
    std::vector<KitDrum> drums;
    bool empty() const { return drums.empty(); }
};

// Two drums' shells must be this far apart in plan view (m): the sticks
// reach each head from above without a shell in the way.
constexpr double kKitMinGap_m = 0.02;

// The built-in kits by name: "standard" (snare, two rack toms, floor tom: a
// right-handed four-piece), "standard-cymbals" (the same with an 18-inch
// crash, a 20-inch ride and a 14-inch hi-hat), "full" (standard-cymbals and a 22-inch
// kick played by the right foot), "standard-timpani" (the four drums and a
// 26-inch timpani to the left of the snare) and "timpani" (two timpani).
// Throws PerformError naming the kits for another name.
Kit kit_named(const std::string &name);
// "standard, standard-cymbals, full, standard-timpani, timpani".
std::string kit_names();
// Throws PerformError naming the drum and the fault: no drums or more than
// kMaxDrums, a bad or repeated name, an unknown preset, a cymbal first (the
// first drum is the one drum's head), a size out of range,
// a MIDI note outside 0..127, two shells closer than kKitMinGap_m in plan.
void validate_kit(const Kit &kit);
// The smallest plan-view gap between two drums' shells (m; +inf for one drum).
double kit_min_gap_m(const Kit &kit);
// The drum's pan in the sound's stereo mix, by its place: -x / 0.8 m within
// +-0.6 (the performer's left, + here, to the left channel).
double kit_drum_pan(const KitDrum &drum);
// Whether the drum is a hi-hat: a cymbal whose preset has a pedal (the
// closed pair's edge loss, docs/plates.md "The hi-hat"), so that its notes
// carry the pedal's openness (docs/kit.md, "The hi-hat").
bool kit_drum_has_pedal(const KitDrum &drum);
// The number of pieces the hands play (the scene's drums): the kit's size
// less its foot pieces, which come last.
int kit_hand_pieces(const Kit &kit);
// The kit's first foot piece, or -1.
int kit_foot_piece(const Kit &kit);
// The drum named `name` (lower case), or -1.
int kit_drum_index(const Kit &kit, const std::string &name);

// The kit in the world: drum i's scene parameters (`base`'s damping and
// friction, the kit's radius, tension and shell), each at
// anchor_m + place_m in the frame (right, up, forward). The foot pieces
// (KitDrum::foot) are not in the scene: the result has the hands' pieces only.
std::vector<DrumParams> place_kit(const Kit &kit, const DrumParams &base,
                                  const Eigen::Vector3d &anchor_m,
                                  const Eigen::Vector3d &right, const Eigen::Vector3d &up,
                                  const Eigen::Vector3d &forward);

} // namespace ictus
