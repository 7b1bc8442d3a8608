"""ArviZ ``InferenceData`` from the results of :func:`chatter.update` and
:func:`chatter.diagnose`, for trace and pair plots, R-hat / ESS and LOO / WAIC with the usual
ArviZ tools. ``idata.to_netcdf("posterior.nc")`` writes the netCDF-4 file (needs ``h5netcdf``
or ``netCDF4``).
"""

from __future__ import annotations

import numpy as np


def _equal_weight_draws(samples: np.ndarray, weights: np.ndarray, seed: int) -> np.ndarray:
    """The samples themselves when their weights are equal (TMCMC, iTMCMC); otherwise (the
    adaptive-MCMC sampler's weighted set) a systematic resample of as many draws, seeded, so
    that ArviZ, which takes every draw as equally weighted, sees the weighted posterior."""
    w = np.asarray(weights, dtype=float)
    if w.size == 0 or np.allclose(w, w[0], rtol=1e-12, atol=0.0):
        return samples
    p = w / w.sum()
    n = len(p)
    u = (np.random.default_rng(seed).random() + np.arange(n)) / n
    index = np.minimum(np.searchsorted(np.cumsum(p), u), n - 1)
    return samples[index]


def update_inference_data(result: dict, seed: int = 0):
    """An ``arviz.InferenceData`` of an :func:`chatter.update` result.

    Groups: ``posterior`` (one chain, one variable per sampled parameter in the units of its
    name; dimensionless perturbations ``theta_*``), ``prior`` (the prior draws of the same
    parameters), ``log_likelihood`` (variable ``y``, nats, one column per observation: each
    identified pole with its repetitions expanded, or each cut; present when the update was run
    with ``pointwise=True``). Attributes: the selected class ``selected_alpha`` and its
    ``log_evidence`` (nats). ``seed`` seeds the resampling of a weighted sample set only.
    """
    import arviz as az

    names = list(result["parameter_names"])
    samples = _equal_weight_draws(np.asarray(result["samples"]), result["weights"], seed)
    prior = np.asarray(result["prior_draws"])
    posterior = {n: samples[None, :, k] for k, n in enumerate(names)}
    prior_group = {n: prior[None, :, k] for k, n in enumerate(names)}
    kwargs = {}
    if "log_likelihood" in result:
        ll = np.asarray(result["log_likelihood"])
        w = np.asarray(result["weights"])
        if not np.allclose(w, w[0], rtol=1e-12, atol=0.0):
            raise ValueError(
                "log_likelihood of a weighted sample set: run update with an equally weighted "
                "sampler (itmcmc, tmcmc) for LOO / WAIC"
            )
        kwargs["log_likelihood"] = {"y": ll[None, :, :]}
        kwargs["dims"] = {"y": ["observation"]}
    selected = [c for c in result["classes"] if c.get("alpha") == result["selected_alpha"]]
    attrs = {"program": "chatter", "selected_alpha": float(result["selected_alpha"] or np.nan)}
    if selected:
        attrs["log_evidence"] = float(selected[0]["log_evidence"])
    return az.from_dict(posterior=posterior, prior=prior_group, attrs=attrs, **kwargs)


def diagnosis_inference_data(diagnosis: dict) -> dict:
    """One ``arviz.InferenceData`` per effect class of a :func:`chatter.diagnose` result, keyed
    by class name: ``posterior`` from the class's ``posterior_samples`` (one chain; variables
    named as the class's fitted parameters, units in the names), and when the diagnosis was run
    with ``pointwise=True`` (the default) ``prior`` (the class's prior draws) and
    ``log_likelihood`` (variable ``y``, nats, one column per observation: the cuts in the order
    given, then the poles) for LOO / WAIC; ``log_evidence`` (nats) and ``probability`` as
    attributes. ``chatter diagnose --out DIR --netcdf`` writes the same groups to
    ``DIR/inference_data/CLASS.nc``."""
    import arviz as az

    out = {}
    for c in diagnosis["classes"]:
        samples = c.get("posterior_samples")
        if samples is None or len(samples) == 0:
            continue
        names = list(c["posterior_parameter_names"])
        s = np.asarray(samples, dtype=float)
        posterior = {n: s[None, :, k] for k, n in enumerate(names)}
        kwargs = {}
        if "prior_draws" in c:
            p = np.asarray(c["prior_draws"], dtype=float)
            kwargs["prior"] = {n: p[None, :, k] for k, n in enumerate(names)}
        if "log_likelihood" in c:
            kwargs["log_likelihood"] = {"y": np.asarray(c["log_likelihood"])[None, :, :]}
            kwargs["dims"] = {"y": ["observation"]}
        out[c["name"]] = az.from_dict(
            posterior=posterior,
            attrs={"log_evidence": float(c["log_evidence"]), "probability": float(c["probability"])},
            **kwargs,
        )
    return out
