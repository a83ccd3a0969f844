/* membrane_presets.c -- the preset table (membrane_presets.h). Values and sources:
 * docs/sound.md, "Presets". Heads are Mylar (polyethylene terephthalate, 1380 kg/m^3):
 * surface density = 1380 x thickness; single-ply batter heads are 0.19-0.25 mm thick.
 * Tensions are tuning choices that put the lowest partial where the instrument of that
 * size is commonly tuned: T = sigma (2 pi a f / j)^2 for the wanted f. */
#include "membrane_presets.h"

#include "ictus_name.h"

/* The cymbals' energy cascade: 1, the rate of the in-plane stress's frequency shift
 * (docs/plates.md, "The cascade"). */
#define CYMBAL_CASCADE 3.0
/* A drum head's: 1, the fundamental's rate at a tenth of a frequency shift
 * (docs/membrane.md, "The energy cascade"). Off on the floor tom and the kick (their slack
 * heads would carry it past the top of their 1024 modes at ff) and on the snare (under its
 * wires' air the batter's updates wait, as its tension modulation's). */
#define DRUM_CASCADE 1.0

/* clang-format off */
static const membrane_preset presets[] = {
    /* The head of the paper's figures and of the Bessel tests: membrane.h's head without tension modulation or physical losses. */
    {"paper", "14-inch Mylar head, 0.19 mm, 3000 N/m, linear (the paper's head)",
     0.178, 3000.0, 0.262, 1.0, 1.0, 128, 0.3, {0.5, 0.5}, {0.0, 90.0}, 0, {0}, 1.0, 0, 1, 0, 0.0, 0.0, 0.0, 0.0},
    /* 14-inch snare, 0.25 mm batter (0.345 kg/m^2), (0,1) at 220 Hz. */
    {"snare", "14-inch snare drum, 0.25 mm Mylar batter, (0,1) at 220 Hz",
     0.1778, 3603.0, 0.345, 0.5, 1.0, 0, 0.3, {0.5, 0.5}, {0.0, 90.0}, 0, {0}, 1.0, 1, 0, 0, 0.0, 0.0, 0.0, 0.0},
    /* 12-inch rack tom, a two-ply batter (2 x 0.178 mm, the common tom head), the air's
     * mass on both faces (airmass 2: the room's above, the shell's below), (0,1) at
     * 110 Hz with it. */
    {"tom", "12-inch tom, two-ply Mylar batter (2 x 0.178 mm), the air on both faces, (0,1) at 110 Hz",
     0.1524, 1465.7, 0.491, 0.8, 1.0, 1024, 0.3, {0.5, 0.5}, {0.0, 90.0}, 0, {0}, 1.0, 0, 0, 0, 0.0, 0.0, DRUM_CASCADE, 2.0},
    /* 16-inch floor tom, 0.25 mm batter, (0,1) at 95 Hz. */
    {"floor-tom", "16-inch floor tom, 0.25 mm Mylar batter, (0,1) at 95 Hz",
     0.2032, 878.0, 0.345, 1.2, 1.0, 1024, 0.3, {0.5, 0.5}, {0.0, 90.0}, 0, {0}, 1.0, 0, 0, 0, 0.0, 0.0, 0.0, 0.0},
    /* 26-inch timpani, 0.19 mm head (0.262 kg/m^2), (1,1) at 110 Hz (A2) once air-loaded:
     * the kettle's air makes (m,1) near harmonic (Rossing 2000): 1 : 1.50 : 1.98 : 2.44 :
     * 2.90; (5,1) keeps its ideal frequency, so the ideal (1,1) is 110 / 0.789 Hz.
     * Struck a quarter of the way in from the rim; (0,1) radiates and dies fast. */
    {"timpani", "26-inch timpani, 0.19 mm Mylar, kettle-loaded, (1,1) at 110 Hz",
     0.3302, 1493.0, 0.262, 3.0, 0.3, 1024, 0.75, {0.75, 0.6}, {0.0, 90.0},
     6, {0.0, 1.0, 1.50, 1.98, 2.44, 2.90}, 10.0, 0, 0, 0, 0.0, 0.0, DRUM_CASCADE, 0.0},
    /* 18-inch frame drum: no shell, a thin head at low tension, (0,1) at 80 Hz. */
    {"frame", "18-inch frame drum, 0.19 mm Mylar, no shell, (0,1) at 80 Hz",
     0.2286, 599.0, 0.262, 0.4, 2.0, 1024, 0.5, {0.5, 0.5}, {0.0, 90.0}, 0, {0}, 1.0, 0, 0, 0, 0.0, 0.0, DRUM_CASCADE, 0.0},
    /* 22-inch bass drum (kick), 0.25 mm batter, (0,1) at 55 Hz, muffled (a pad inside
     * touching the head, as most kit kicks are: T60 0.4 s); the beater strikes near the
     * centre. Played with the felt tip (stick_tip.h). */
    {"kick", "22-inch bass drum, 0.25 mm Mylar batter, (0,1) at 55 Hz, muffled",
     0.2794, 556.1, 0.345, 0.4, 1.0, 1024, 0.15, {0.5, 0.5}, {0.0, 90.0}, 0, {0}, 1.0, 0, 0, 0, 0.0, 0.0, 0.0, 0.0},
    /* Cymbals: flat free-edge plates of cymbal bronze (CuSn20: E 100 GPa, 8600 kg/m^3,
     * nu 0.33), D = E h^3 / (12 (1 - nu^2)), density 8600 h; docs/plates.md. An 18-inch
     * crash 1.0 mm thick, struck at the edge; modes to about 18 kHz. */
    {"crash", "18-inch crash cymbal, 1.0 mm bronze plate, free edge",
     0.2286, 0.0, 8.6, 4.0, 0.0, 1400, 0.9, {0.5, 0.7}, {0.0, 90.0}, 0, {0}, 1.0, 0, 0,
     1, 9.35, 0.0, CYMBAL_CASCADE, 0.0},
    /* A 20-inch ride 1.4 mm thick, struck on the bow; modes to about 16 kHz. */
    {"ride", "20-inch ride cymbal, 1.4 mm bronze plate, free edge",
     0.254, 0.0, 12.04, 6.0, 0.0, 1400, 0.6, {0.5, 0.7}, {0.0, 90.0}, 0, {0}, 1.0, 0, 0,
     1, 25.66, 0.0, CYMBAL_CASCADE, 0.0},
    /* A 14-inch hi-hat: the top cymbal 1.1 mm thick (a flat disc of 0.94 kg), struck on
     * the bow; the bottom cymbal is the loss along its edge when the pedal closes the
     * pair (edgedamp, docs/plates.md "The hi-hat"); modes to about 22 kHz. edgedamp 20
     * N s/m^2 is a choice: 2.5 % of what a bottom plate taking every bending wave that
     * reaches the edge would be (rho h c_B, 800 N s/m^2 at 1 kHz): the plates touch at
     * places, not all round, and the bottom one gives back much of what it takes. */
    {"hihat", "14-inch hi-hat, 1.1 mm bronze top plate, the bottom plate on its edge",
     0.1778, 0.0, 9.46, 3.0, 0.0, 1000, 0.7, {0.5, 0.7}, {0.0, 90.0}, 0, {0}, 1.0, 0, 0,
     1, 12.45, 20.0, CYMBAL_CASCADE, 0.0},
};
/* clang-format on */

#define PRESET_COUNT (int)(sizeof(presets) / sizeof(presets[0]))

int membrane_preset_count(void)
{
    return PRESET_COUNT;
}

const membrane_preset *membrane_preset_at(int index)
{
    return index >= 0 && index < PRESET_COUNT ? &presets[index] : NULL;
}

const membrane_preset *membrane_preset_find(const char *name)
{
    for (int i = 0; name && i < PRESET_COUNT; i++)
        if (ictus_name_equal(presets[i].name, name))
            return &presets[i];
    return NULL;
}

const char *membrane_preset_names(void)
{
    return "paper, snare, tom, floor-tom, timpani, frame, kick, crash, ride, hihat";
}

const char *membrane_preset_drum_names(void)
{
    return "paper, snare, tom, floor-tom, timpani, frame, kick";
}
