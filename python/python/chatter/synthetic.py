"""A synthetic fleet for trying batch runs: campaigns of the gap diagnosis's proving ground
written as files with their manifest."""

from __future__ import annotations

import json
from pathlib import Path

from ._chatter import synthetic_campaign

EFFECTS = ("none", "parameter_error", "process_damping", "speed_dependent_dynamics",
           "extra_mode", "drift")


def write_fleet(folder, campaigns: int, cuts: int = 8, pole_speeds: int = 0) -> Path:
    """Write ``campaigns`` small synthetic milling campaigns (the hidden effects in turn, at
    magnitude 2, each with its own seed) and ``manifest.csv`` into ``folder``; return the
    manifest's path."""
    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    lines = ["name,model,observations,seed"]
    for i in range(campaigns):
        effect = EFFECTS[i % len(EFFECTS)]
        model, observations = synthetic_campaign(effect, 2.0, seed=1000 + i, cuts=cuts,
                                                 pole_speeds=pole_speeds)
        (folder / f"m{i:03}.json").write_text(json.dumps(model))
        (folder / f"o{i:03}.json").write_text(json.dumps(observations))
        lines.append(f"machine-{i:03}-{effect},m{i:03}.json,o{i:03}.json,{i}")
    manifest = folder / "manifest.csv"
    manifest.write_text("\n".join(lines) + "\n")
    return manifest
