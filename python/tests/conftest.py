"""Shared paths and the `chatter` command-line program the Python results are compared with."""

import os
import shutil
import subprocess
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]
EXAMPLES = REPO / "examples"
TURNING_MODEL = EXAMPLES / "ahmadi2022_turning_model.json"
TURNING_OBSERVATIONS = EXAMPLES / "ahmadi2022_turning_observations.json"
MILLING_MODEL = EXAMPLES / "schmitz2023_milling_model.json"
POSTERIOR_EQ34 = EXAMPLES / "ahmadi2022_posterior.json"
RCSA_MODEL = EXAMPLES / "schmitz2022_rcsa_model.json"
RCSA_PRIOR = EXAMPLES / "schmitz2022_rcsa_prior.json"


def _find_cli():
    given = os.environ.get("CHATTER_BIN")
    if given:
        return given
    roots = [os.environ.get("CARGO_TARGET_DIR"), str(REPO / "target")]
    for root in filter(None, roots):
        for profile in ("release", "debug"):
            p = Path(root) / profile / "chatter"
            if p.exists():
                return str(p)
    return shutil.which("chatter")


@pytest.fixture(scope="session")
def cli():
    """Run the `chatter` binary (CHATTER_BIN, else target/{release,debug}/chatter); in CI a
    missing binary is an error, elsewhere the comparison tests are skipped."""
    binary = _find_cli()
    if binary is None:
        if os.environ.get("CI"):
            pytest.fail("CHATTER_BIN is not set and no chatter binary was built")
        pytest.skip("no chatter binary: build it with cargo build -p chatter-cli or set CHATTER_BIN")

    def run(*args):
        done = subprocess.run(
            [binary, "--quiet", *map(str, args)], capture_output=True, text=True
        )
        assert done.returncode == 0, done.stderr
        return done.stdout

    return run
