"""Machining chatter from Python: stability lobes, uncertainty bands, simulation, OMA and
chatter detection, Bayesian updating, test planning, sim-to-real gap diagnosis and fleet runs.

The numbers come from the same Rust library functions as the ``chatter`` command line, so the
same inputs and seed give bit-identical results. Units are in every name: ``speed_rpm``,
``depth_mm``, ``frequency_hz``; log-evidences and log-likelihoods are in nats.

Models and observations are given as a path (JSON, or a cuts CSV for observations) or as a
dict in the file format of the README. Long calls release the GIL and stop on Ctrl-C: the
libraries are cancelled inside (between speeds, samples and sampler moves) before
``KeyboardInterrupt`` is raised.
"""

from ._chatter import (  # noqa: F401
    __version__,
    bands_geometric,
    bands_montecarlo,
    bands_perturbation,
    batch,
    campaign_table,
    detect,
    diagnose,
    load_model,
    load_observations,
    lobes,
    multiplier,
    rcsa,
    sensitivity,
    oma,
    oma_observations,
    plan,
    read_manifest,
    run_campaign,
    simulate,
    synthetic_campaign,
    update,
    validate,
)
from .inference import diagnosis_inference_data, update_inference_data  # noqa: F401
from .fleet import run_dask  # noqa: F401
from .synthetic import write_fleet  # noqa: F401
