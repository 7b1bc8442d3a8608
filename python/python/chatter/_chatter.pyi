"""Type hints of the compiled module. Units are in every name; dicts of numpy arrays out."""

from os import PathLike
from typing import Any, Optional, Sequence, Union

import numpy as np
import numpy.typing as npt

Source = Union[str, PathLike, dict]
"""A path to a JSON file (observations: or a cuts CSV), or a dict in the file format."""
Distribution = Union[str, PathLike, dict]
"""A posterior folder of ``chatter update``, a covariance file, a dict
``{"parameter_names", "covariance", "mean"}`` or an :func:`update` result."""
Array = npt.NDArray[np.float64]

__version__: str

def load_model(model: Source) -> dict:
    """Read and validate a model; the model-file dict (``frequency_hz``, ``stiffness_n_per_m``, ...)."""

def load_observations(observations: Source) -> dict:
    """Read and validate observations (``cuts``: ``speed_rpm``, ``depth_mm``, ``stable``,
    ``chatter_hz``; ``poles``: ``frequency_hz``, ``damping_ratio``)."""

def validate(model: Source, observations: Optional[Source] = None) -> dict:
    """``{"operation", "modes"[, "cuts", "poles", "signals"]}``; ``ValueError`` naming the field."""

def lobes(model: Source, speeds_rpm: Optional[Array] = None, method: str = "fdm") -> dict:
    """Limiting depth per speed: ``speed_rpm`` (rpm), ``depth_mm`` (mm), ``chatter_hz`` (Hz).
    ``method``: "zoa", "fdm" or "sdm"; default speeds those of ``chatter lobes``: the dominant
    mode's lobes, evenly spaced in lobe number (20 speeds per lobe, 200-2000 speeds)."""

def sensitivity(
    model: Source,
    speed_rpm: float,
    depth_mm: float,
    parameters: Optional[list[str]] = None,
    steps_per_revolution: Optional[int] = None,
    map: str = "one-step",
) -> dict:
    """d mu / d theta of the dominant pole at one cut (000 Table 3): the JSON of
    ``chatter sensitivity`` as a dict (``eigenvalue``, ``chatter_hz``, ``sensitivities``)."""

def rcsa(assembly: Union[str, PathLike]) -> dict:
    """Tool-tip FRF of an assembly file by receptance coupling (004 Eq. 1-4): ``frequency_hz``,
    ``real``, ``imag`` (m/N)."""

def multiplier(
    model: Source,
    speed_rpm: float,
    depth_mm: float,
    method: str = "fdm",
    ssv_amplitude_ratio: Optional[float] = None,
    ssv_frequency_ratio: Optional[float] = None,
) -> dict:
    """Dominant Floquet multiplier: ``method``, ``modulus``, ``real``, ``imag``, ``stable`` and
    at constant speed ``frequency_hz`` (principal), ``chatter_hz``, ``kind`` (hopf/flip/fold);
    with a sinusoidal speed variation (both ratios) ``ssv_amplitude_ratio``,
    ``ssv_frequency_ratio`` and ``period_s`` (the multiplier over the variation's period)."""

def bands_geometric(
    model: Source,
    speeds_rpm: Optional[Array] = None,
    offset_rpm: Optional[float] = None,
    offset_mm: Optional[float] = None,
    method: str = "zoa",
) -> dict:
    """Type B offsets (Schmitz 2023): ``speed_rpm``, ``depth_mm``, ``lower_mm``, ``upper_mm``
    (NaN where not covered), ``theta_deg`` (Eq. 2), ``distance`` (Eq. 1, rpm/um units).
    Offsets default to the request's 100 rpm and 0.2 mm (seed 001)."""

def bands_perturbation(
    model: Source,
    distribution: Distribution,
    speeds_rpm: Optional[Array] = None,
    depths_mm: Optional[Array] = None,
    method: str = "fdm",
    coverage: Optional[float] = None,
) -> dict:
    """Second-order credibility bounds (Ahmadi 2022 Eq. 14-18) at the distribution's mean:
    ``speed_rpm``, ``depth_mm``, ``lower_mm``, ``upper_mm`` (NaN where not reached on the
    ``depth_grid_mm``); ``coverage`` (e.g. 0.95) for central credibility of abs(mu)."""

def bands_montecarlo(
    model: Source,
    distribution: Distribution,
    speeds_rpm: Optional[Array] = None,
    samples: Optional[int] = None,
    seed: Optional[int] = None,
    method: str = "fdm",
    map_depths_mm: Optional[Array] = None,
) -> dict:
    """Monte Carlo boundaries (Schmitz 2022): depth quantiles ``lower_mm`` (5 %), ``depth_mm``
    (50 %), ``upper_mm`` (95 %), chatter-frequency quantiles ``chatter_hz_q05/q50/q95`` (Hz),
    ``limits_mm`` (draws x speeds), ``failures``, ``map_depth_mm`` and ``p_stable`` (speeds x depths)."""

def simulate(
    model: Source,
    speed_rpm: float,
    depth_mm: float,
    duration_s: float,
    sample_rate_hz: float,
    seed: int,
    quantity: str = "acceleration",
    random_force_n: float = 1.0,
    harmonic_force_n: float = 0.0,
    feed_per_tooth_mm: float = 0.05,
) -> dict:
    """Time-domain cut: ``names`` (two coordinates, ``once_per_rev``), ``data`` (channels x
    samples, m/s^2, m/s or m), ``sample_rate_hz``, ``lost_contact_fraction``."""

def detect(
    data: Array,
    sample_rate_hz: float,
    speed_rpm: float,
    names: Optional[Sequence[str]] = None,
    once_per_rev_channel: Optional[str] = None,
) -> dict:
    """Chatter detection of one record (rows: channels): ``stable``, ``chatter_hz`` (Hz or
    None), ``evidence`` (``line_hz``, ``line_variation``, ``margin``, dB ratios)."""

def oma(
    data: Array,
    sample_rate_hz: float,
    speed_rpm: Optional[float] = None,
    names: Optional[Sequence[str]] = None,
    seed: int = 0,
) -> dict:
    """Dominant pole of a stable record (modified LSCE with the spindle harmonics):
    ``frequency_hz``, ``frequency_std_hz``, ``damping_ratio``, ``damping_std``, ``repetitions``."""

def oma_observations(
    observations: Source,
    model: Optional[Source] = None,
    min_order: Optional[int] = None,
    max_order: Optional[int] = None,
    segments: Optional[int] = None,
    harmonics_hz: Optional[Sequence[float]] = None,
    decimation: Optional[int] = None,
    interference_hz: Optional[Sequence[float]] = None,
    allow_chatter: bool = False,
) -> dict:
    """OMA of every signal record of an observations file or dict (the ``chatter oma
    --observations FILE`` job): ``observations`` (the command's JSON, the input's cuts with one
    pole per record) and arrays over the records ``speed_rpm``, ``frequency_hz`` (Hz),
    ``damping_ratio``, ``frequency_std_hz``, ``damping_std``. A chattering record is refused
    (``ValueError``) unless ``allow_chatter``; a milling ``model`` makes the identification
    lifted at the tooth period. ``harmonics_hz``: None for the spindle lines, [] for none;
    ``interference_hz``: None to search a mains comb, [] for none."""

def update(
    model: Source,
    observations: Source,
    seed: int,
    sampler: str = "itmcmc",
    samples: int = 5000,
    parameters: Optional[Sequence[str]] = None,
    priors: Optional[Source] = None,
    classes: Optional[Sequence[float]] = None,
    surrogate: str = "gp",
    surrogate_points: int = 400,
    pointwise: bool = True,
    method: Optional[str] = None,
) -> dict:
    """Bayesian updating (the ``chatter update`` job): ``parameter_names``, ``samples``
    (draws x parameters), ``weights``, ``posterior_mean``, ``posterior_covariance``,
    ``classes`` (``alpha``, ``log_evidence`` and ``data_fit`` in nats, ``probability``),
    ``selected_alpha``, ``prior_draws``, ``log_likelihood`` (draws x observations, nats),
    ``updated_model``, ``pole_table``, ``prior_bound_pileups``, ``surrogate``, ``warnings`` (the
    sentences ``chatter update`` prints after ``warning:``). ``priors`` (a dict or a path, the
    ``--priors`` file): marginals by name, or one correlated normal ``{"parameter_names",
    "mean", "covariance"}`` such as 004's RCSA prior (``examples/schmitz2022_rcsa_prior.json``),
    whose names are then the updated parameters unless ``parameters`` is given. ``method``: the
    stability method of a cut likelihood, "fdm" (default), "sdm" or "zoa" (cut results only)."""

def plan(
    model: Source,
    observations: Source,
    strategy: str = "mrr",
    p_test: float = 0.5,
    parameters: Optional[Sequence[str]] = None,
    priors: Optional[Source] = None,
    target: Optional[str] = None,
    paths: int = 300,
    speeds_rpm: Optional[Array] = None,
    depths_mm: Optional[Array] = None,
    feed_per_tooth_mm: float = 0.1,
    seed: int = 0,
    max_tests: int = 10,
    method: Optional[str] = None,
) -> dict:
    """The next test cut (the ``chatter plan`` JSON): ``next_cut`` (``speed_rpm``, ``depth_mm``,
    ``p_stable``, ...), ``stop``, ``posterior_mean``, ``posterior_sd``, ..., ``warnings`` (the
    sentences ``chatter plan`` prints after ``warning:``). ``priors`` as in :func:`update`;
    ``method`` the stability method of the sampled boundaries ("fdm", "sdm" or "zoa")."""

def diagnose(
    model: Source,
    observations: Source,
    seed: int,
    samples: int = 120,
    validation: str = "kfold",
    folds: int = 3,
    pointwise: bool = True,
) -> dict:
    """Sim-to-real gap diagnosis (the ``chatter diagnose`` job, ``diagnosis.json`` contents):
    ``verdict``, ``classes`` (with ``posterior_parameter_names``, ``posterior_samples`` and,
    with ``pointwise``, ``prior_draws`` and ``log_likelihood`` in nats, one column per cut then
    pole), ``regions``, ``residuals``, ``diagnosed_model``, ..."""

def read_manifest(manifest: Union[str, PathLike]) -> list[dict]:
    """Campaigns of a fleet manifest (``name``, ``model``, ``observations``, ``seed``)."""

def run_campaign(
    name: str,
    model: Union[str, PathLike],
    observations: Union[str, PathLike],
    seed: int,
    samples: int = 120,
    paths: int = 300,
    validation: str = "off",
    folds: int = 3,
) -> dict:
    """One campaign: ``line`` (its batch-table line), ``verdict``, ``boundary_shift_percent`` (%),
    ``next_speed_rpm``, ``next_depth_mm``, ``next_p_stable``, ``stop``; or ``error``."""

def batch(
    manifest: Union[str, PathLike],
    samples: int = 120,
    paths: int = 300,
    validation: str = "off",
    folds: int = 3,
) -> str:
    """Every campaign of the manifest in parallel here (rayon): the table text."""

def campaign_table(lines: list[str]) -> str:
    """The batch table of table lines (header first)."""

def synthetic_campaign(
    effect: str, magnitude: float, seed: int, cuts: int = 32, pole_speeds: Optional[int] = None
) -> tuple[dict, dict]:
    """A synthetic milling campaign (model dict, observations dict) with a hidden ``effect``
    ("none", "parameter_error", "process_damping", ...) at ``magnitude``; poles at
    ``pole_speeds`` speeds spread over the range (None: 3000, 6000, 9000, 12 000 rpm, as in
    ``chatter demo``)."""
