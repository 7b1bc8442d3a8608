"""Jobs moved from the command line into `chatter-jobs`: the Python call and the CLI build the
same request, so their numbers are bit-equal (the CLI writes round-trip digits)."""

import csv
import json

import numpy as np

import chatter
from conftest import EXAMPLES, MILLING_MODEL, TURNING_MODEL

RCSA_ASSEMBLY = EXAMPLES / "schmitz2022_rcsa_assembly.json"


def test_sensitivity_is_the_cli_json(cli):
    # 000 Table 3's condition P1 on the seed-000 lathe, both maps, default and named parameters
    for extra, kwargs in [
        ((), {}),
        (("--map", "period", "--parameters", "theta_omega_2,theta_k_1"),
         {"map": "period", "parameters": ["theta_omega_2", "theta_k_1"]}),
        (("--steps-per-revolution", "120"), {"steps_per_revolution": 120}),
    ]:
        text = cli("sensitivity", "--model", TURNING_MODEL, "--speed-rpm", 7150,
                   "--depth-mm", 2.286, *extra)
        py = chatter.sensitivity(TURNING_MODEL, 7150.0, 2.286, **kwargs)
        assert json.loads(text) == py, extra


def test_sensitivity_names_the_bad_keyword():
    import pytest
    with pytest.raises(ValueError, match="steps_per_revolution 1: expected at least 2"):
        chatter.sensitivity(TURNING_MODEL, 7150.0, 2.286, steps_per_revolution=1)
    with pytest.raises(ValueError, match="map `monodromy`"):
        chatter.sensitivity(TURNING_MODEL, 7150.0, 2.286, map="monodromy")
    # the one-step map is turning only (000 Table 3 is a lathe)
    with pytest.raises(ValueError):
        chatter.sensitivity(MILLING_MODEL, 9000.0, 1.0)


def test_rcsa_is_the_cli_csv(cli, tmp_path):
    out = tmp_path / "tip.csv"
    cli("rcsa", "--assembly", RCSA_ASSEMBLY, "--out", out)
    with open(out) as f:
        rows = list(csv.DictReader(f))
    py = chatter.rcsa(RCSA_ASSEMBLY)
    for key, column in [("frequency_hz", "frequency_hz"), ("real", "real_m_per_n"),
                        ("imag", "imag_m_per_n")]:
        assert np.array_equal(py[key], np.array([float(r[column]) for r in rows])), key
