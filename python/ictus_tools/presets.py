"""A drum preset's head as externals/core/membrane_presets.c lays it (docs/sound.md,
"Presets"), read from the table's text for tests and tools: radius, tension, density and
the air's mass (airmass, the row's last field)."""
import os

from ictus_tools import ROOT

TABLE = os.path.join(ROOT, "externals", "core", "membrane_presets.c")


def _row(name):
    """The numbers of a preset's row, in the table's order, braces flattened."""
    with open(TABLE) as f:
        text = f.read()
    i = text.index('{"%s",' % name)
    body = text[text.index('",', text.index('",', i) + 2) + 2:]
    depth, end = 0, 0
    for end, ch in enumerate(body):
        depth += ch == "{"
        if ch == "}":
            if depth == 0:
                break
            depth -= 1
    words = body[:end].replace("{", " ").replace("}", " ").replace(",", " ").split()
    return words


def preset_head(name):
    """(radius m, tension N/m, density kg/m^2) of a preset."""
    return tuple(float(w) for w in _row(name)[:3])


def preset_air_mass(name):
    """The preset's airmass (0: no air on the head)."""
    return float(_row(name)[-1])
