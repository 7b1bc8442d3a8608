"""Seed 000 (Ahmadi 2022, turning) step by step, as in a notebook: load the model and the
identified poles, update the modal parameters, inspect the posterior with ArviZ (summary,
trace, LOO), save it as netCDF, and draw the credibility bands of the updated model with
matplotlib.

    python python/examples/seed000.py OUT_DIR [--samples 1000] [--seed 0]

Writes OUT_DIR/trace.png, OUT_DIR/bands.png and OUT_DIR/posterior.nc.
"""

from __future__ import annotations

import argparse
import os
from pathlib import Path

import matplotlib

matplotlib.use("Agg")  # files, no display

import arviz as az  # noqa: E402
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import chatter  # noqa: E402

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"
MODEL = EXAMPLES / "ahmadi2022_turning_model.json"
OBSERVATIONS = EXAMPLES / "ahmadi2022_turning_observations.json"


def run(out_dir: str, samples: int = 1000, seed: int = 0, speeds: int = 19) -> dict:
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)

    # 1. The files: validated on load (units in every key)
    model = chatter.load_model(MODEL)
    observations = chatter.load_observations(OBSERVATIONS)
    print(f"{len(model['modes'])} modes, {len(observations['poles'])} identified poles, "
          f"{len(observations['cuts'])} test cuts")

    # 2. Bayesian updating over the model classes alpha (iTMCMC, seeded)
    result = chatter.update(MODEL, OBSERVATIONS, seed=seed, samples=samples)
    print("parameters:", result["parameter_names"], "selected alpha:", result["selected_alpha"])

    # 3. ArviZ: summary, trace plot, LOO from the pointwise log-likelihood, netCDF
    idata = chatter.update_inference_data(result)
    print(az.summary(idata, kind="stats"))
    az.plot_trace(idata)
    plt.savefig(out / "trace.png", dpi=80)
    plt.close("all")
    loo = az.loo(idata)
    print(loo)
    idata.to_netcdf(str(out / "posterior.nc"))

    # 4. Credibility bands of the updated model (000 Eq. 14-18) over the nominal lobes
    speeds_rpm = np.linspace(6800.0, 7700.0, speeds)
    nominal = chatter.lobes(MODEL, speeds_rpm=speeds_rpm)
    bands = chatter.bands_perturbation(MODEL, result, speeds_rpm=speeds_rpm)
    fig, ax = plt.subplots(figsize=(7, 4.5))
    ax.plot(nominal["speed_rpm"], nominal["depth_mm"], "k--", label="nominal model")
    ax.plot(bands["speed_rpm"], bands["depth_mm"], "b-", label="updated: |E mu| = 1")
    ax.fill_between(bands["speed_rpm"], bands["lower_mm"], bands["upper_mm"], color="b",
                    alpha=0.2, label="+- 1 sd of mu")
    cuts = observations["cuts"]
    for stable, marker in ((True, "o"), (False, "x")):
        pts = [(c["speed_rpm"], c["depth_mm"]) for c in cuts if c["stable"] == stable]
        if pts:
            ax.plot(*zip(*pts), marker, color="g" if stable else "r", linestyle="none",
                    label="stable cut" if stable else "chatter")
    ax.set_xlabel("spindle speed (rpm)")
    ax.set_ylabel("width of cut (mm)")
    ax.legend()
    fig.savefig(out / "bands.png", dpi=80)
    plt.close(fig)
    return {"result": result, "idata": idata, "loo": loo, "bands": bands, "nominal": nominal}


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("out_dir")
    parser.add_argument("--samples", type=int, default=1000)
    parser.add_argument("--seed", type=int, default=0)
    a = parser.parse_args()
    run(a.out_dir, a.samples, a.seed)
    print("wrote", ", ".join(sorted(os.listdir(a.out_dir))))
