"""The Python package: inputs, the science calls against analytic or independent values, the
numbers bit-equal to the command line's for the same seed, interruption, ArviZ output."""

import _thread
import csv
import json
import re
import threading
import time

import numpy as np
import pytest

import chatter
from conftest import (MILLING_MODEL, POSTERIOR_EQ34, RCSA_MODEL, RCSA_PRIOR, TURNING_MODEL,
                      TURNING_OBSERVATIONS)


def read_csv(path):
    with open(path) as f:
        return list(csv.DictReader(f))


def cells(rows, key):
    """A CSV column as floats, NaN for empty cells (exact: the CLI writes round-trip digits)."""
    return np.array([float(r[key]) if r[key] != "" else np.nan for r in rows])


def same(a, b):
    """Bit-equal arrays, NaN equal to NaN."""
    a, b = np.asarray(a, float), np.asarray(b, float)
    return a.shape == b.shape and np.array_equal(a, b, equal_nan=True)


# --- inputs ---------------------------------------------------------------------------------


def test_model_from_path_and_from_dict_agree():
    m = chatter.load_model(TURNING_MODEL)
    assert [mode["frequency_hz"] for mode in m["modes"]] == [1842.0, 2445.0]
    assert chatter.load_model(m) == m


def test_bad_input_names_the_field_and_value():
    d = json.loads(TURNING_MODEL.read_text())
    d["modes"][0]["damping_ratio"] = -0.1
    with pytest.raises(ValueError, match="damping_ratio"):
        chatter.load_model(d)
    with pytest.raises(ValueError, match="no_such.json"):
        chatter.load_model("no_such.json")
    with pytest.raises(ValueError, match='method "euler"'):
        chatter.lobes(TURNING_MODEL, method="euler")
    with pytest.raises(ValueError, match="samples 3"):
        chatter.update(TURNING_MODEL, TURNING_OBSERVATIONS, seed=0, samples=3)


def test_validate_summarizes_the_seed_000_files():
    v = chatter.validate(TURNING_MODEL, TURNING_OBSERVATIONS)
    assert v == {"operation": "turning", "modes": 2, "cuts": 7, "poles": 5, "signals": 0}


# --- science against independent values -----------------------------------------------------


def single_mode_turning(k=2e7, zeta=0.03, f_hz=800.0, kn=400.0):
    """One mode along the feed, whose regenerative force is kn b h along the feed."""
    return {
        "operation": {"kind": "turning"},
        "cutting": {"kt_n_per_mm2": 1000.0, "kn_n_per_mm2": kn},
        "modes": [
            {"frequency_hz": f_hz, "damping_ratio": zeta,
             "direction": "feed", "stiffness_n_per_m": k}
        ],
    }


def test_zero_order_lobe_minimum_is_the_single_mode_closed_form():
    # b_lim,min = 2 k zeta (1 + zeta) / K (Tlusty; Altintas 2012 Eq. 3.17 at min Re G), in mm
    k, zeta, kn = 2e7, 0.03, 400.0
    expected_mm = 2 * k * zeta * (1 + zeta) / (kn * 1e6) * 1e3
    speeds = np.linspace(2000.0, 20000.0, 4000)
    lobes = chatter.lobes(single_mode_turning(k, zeta, kn=kn), speeds_rpm=speeds, method="zoa")
    # the grid minimum lies within the lobe's flat bottom: 1e-3 relative
    assert np.nanmin(lobes["depth_mm"]) == pytest.approx(expected_mm, rel=1e-3)


def test_multiplier_crosses_one_at_the_limiting_depth():
    # the lobes refine the discretization (Richardson) beyond the multiplier's fixed grid, so
    # |mu| = 1 holds at the limit to the grid's accuracy (< 0.5 % in depth): 3 % either side
    speeds = np.array([3000.0, 5000.0])
    lobes = chatter.lobes(MILLING_MODEL, speeds_rpm=speeds, method="fdm")
    for s, b in zip(speeds, lobes["depth_mm"]):
        assert chatter.multiplier(MILLING_MODEL, float(s), 0.97 * float(b))["modulus"] < 1.0
        assert chatter.multiplier(MILLING_MODEL, float(s), 1.03 * float(b))["modulus"] > 1.0


def test_simulated_cuts_are_detected_stable_below_and_chatter_above_the_limit():
    speed = 7000.0
    limit = float(chatter.lobes(TURNING_MODEL, speeds_rpm=np.array([speed]))["depth_mm"][0])
    verdicts = []
    for ratio in (0.3, 2.0):
        sim = chatter.simulate(TURNING_MODEL, speed, ratio * limit, duration_s=1.0,
                               sample_rate_hz=20000.0, seed=1)
        assert sim["names"][-1] == "once_per_rev"
        assert sim["data"].shape == (3, 20000)
        d = chatter.detect(sim["data"], sim["sample_rate_hz"], speed, names=sim["names"],
                           once_per_rev_channel="once_per_rev")
        verdicts.append(d["stable"])
    assert verdicts == [True, False]


def _stable_and_chattering_records(tmp_path):
    """Observations listing two simulated turning cuts at 7000 rpm (CSV, with the tachometer):
    0.3 and 2 times the limiting depth."""
    speed = 7000.0
    limit = float(chatter.lobes(TURNING_MODEL, speeds_rpm=np.array([speed]))["depth_mm"][0])
    entries = []
    for k, ratio in enumerate((0.3, 2.0)):
        sim = chatter.simulate(TURNING_MODEL, speed, ratio * limit, duration_s=2.0,
                               sample_rate_hz=20000.0, seed=1)
        path = tmp_path / f"cut{k}.csv"
        with open(path, "w") as f:
            f.write(",".join(sim["names"]) + "\n")
            for row in sim["data"].T:
                f.write(",".join(repr(float(v)) for v in row) + "\n")
        entries.append({"file": str(path), "speed_rpm": speed, "depth_mm": ratio * limit,
                        "sample_rate_hz": sim["sample_rate_hz"],
                        "once_per_rev_channel": "once_per_rev"})
    return entries


def test_oma_of_an_observations_file_equals_the_cli(cli, tmp_path):
    stable, chattering = _stable_and_chattering_records(tmp_path)
    obs = tmp_path / "obs.json"
    obs.write_text(json.dumps({"cuts": [], "signals": [stable]}))
    text = cli("oma", "--observations", obs, "--model", TURNING_MODEL)
    py = chatter.oma_observations(obs, model=TURNING_MODEL)
    assert py["observations"] == json.loads(text)
    pole = py["observations"]["poles"][0]
    assert py["frequency_hz"].shape == (1,)
    assert same(py["frequency_hz"], [pole["frequency_hz"]])
    assert same(py["damping_ratio"], [pole["damping_ratio"]])
    assert same(py["speed_rpm"], [7000.0])
    # the same record as a dict of observations; a chattering record is refused, or flagged
    both = {"cuts": [], "signals": [stable, chattering]}
    with pytest.raises(ValueError, match=r"signals\[1\].*chatter detection calls this record"):
        chatter.oma_observations(both, model=TURNING_MODEL)
    # allowed through, the chattering record is identified with its limit cycle rejected as a
    # spectral line, and its pole carries the detection's flag, never passed as a clean one
    flagged = chatter.oma_observations(both, model=TURNING_MODEL, allow_chatter=True)
    chattering_pole = flagged["observations"]["poles"][1]
    assert chattering_pole["depth_mm"] == chattering["depth_mm"]
    detected = re.search(r"FLAGGED: chatter detection calls the record chatter at ([0-9.]+) Hz",
                         chattering_pole["note"])
    assert detected, chattering_pole["note"]
    note = chattering_pole["note"]
    lines = [float(f) for f in re.findall(r"([0-9.]+) Hz \(SpectralLine\)", note)]
    assert any(abs(f - float(detected.group(1))) < 1.0 for f in lines), note


# --- the same numbers as the command line ---------------------------------------------------


@pytest.fixture(scope="module")
def seed000_update(cli, tmp_path_factory):
    out = tmp_path_factory.mktemp("update")
    cli("update", "--model", TURNING_MODEL, "--observations", TURNING_OBSERVATIONS,
        "--samples", 200, "--seed", 7, "--out", out, "--netcdf")
    py = chatter.update(TURNING_MODEL, TURNING_OBSERVATIONS, seed=7, samples=200)
    return out, py


def test_update_is_bit_identical_to_the_cli(seed000_update):
    out, py = seed000_update
    rows = read_csv(out / "posterior.csv")
    names = py["parameter_names"]
    assert list(rows[0].keys()) == names + ["weight"]
    cli_samples = np.array([[float(r[n]) for n in names] for r in rows])
    assert same(cli_samples, py["samples"])
    assert same(cells(rows, "weight"), py["weights"])
    summary = json.loads((out / "summary.json").read_text())
    assert summary["selected_alpha"] == py["selected_alpha"]
    assert [c["log_evidence"] for c in summary["classes"]] == \
        [c["log_evidence"] for c in py["classes"]]
    assert same(summary["posterior_covariance"], py["posterior_covariance"])


def test_update_with_the_004_correlated_prior_is_bit_identical_to_the_cli(cli, tmp_path):
    """004's joint normal RCSA prior as a path and as a dict: its eight names are the updated
    parameters, and the posterior equals `chatter update --priors FILE` bit for bit."""
    cuts = {"cuts": [{"speed_rpm": 10985.0, "depth_mm": 0.65, "stable": True},
                     {"speed_rpm": 10985.0, "depth_mm": 0.7, "stable": False},
                     {"speed_rpm": 10000.0, "depth_mm": 0.6, "stable": False}]}
    observations = tmp_path / "cuts.json"
    observations.write_text(json.dumps(cuts))
    out = tmp_path / "posterior"
    cli("update", "--model", RCSA_MODEL, "--observations", observations, "--priors", RCSA_PRIOR,
        "--method", "zoa", "--samples", 200, "--seed", 2, "--out", out)
    rows = read_csv(out / "posterior.csv")
    summary = json.loads((out / "summary.json").read_text())
    prior = json.loads(RCSA_PRIOR.read_text())
    for given in (RCSA_PRIOR, prior):
        py = chatter.update(RCSA_MODEL, cuts, seed=2, samples=200, priors=given, method="zoa",
                            pointwise=False)
        names = py["parameter_names"]
        assert names == prior["parameter_names"] == summary["parameter_names"]
        assert same(np.array([[float(r[n]) for n in names] for r in rows]), py["samples"])
        assert same(cells(rows, "weight"), py["weights"])
        assert [c["log_evidence"] for c in summary["classes"]] == \
            [c["log_evidence"] for c in py["classes"]]
        assert same(summary["posterior_covariance"], py["posterior_covariance"])
    # a prior naming a parameter the model does not have is refused naming it
    bad = dict(prior, parameter_names=["no_such"] + prior["parameter_names"][1:])
    with pytest.raises(ValueError, match="no_such"):
        chatter.update(RCSA_MODEL, cuts, seed=2, samples=200, priors=bad, method="zoa")


def test_montecarlo_and_perturbation_bands_are_bit_identical_to_the_cli(cli, seed000_update, tmp_path):
    posterior, _ = seed000_update
    speeds = np.linspace(6900.0, 7500.0, 4)
    spec = "6900:7500:4"
    mc_csv = tmp_path / "mc.csv"
    cli("bands", "--model", TURNING_MODEL, "--kind", "montecarlo", "--posterior", posterior,
        "--samples", 12, "--seed", 3, "--speeds", spec, "--out", mc_csv)
    mc = chatter.bands_montecarlo(TURNING_MODEL, str(posterior), speeds_rpm=speeds, samples=12,
                                  seed=3)
    rows = read_csv(mc_csv)
    for key in ("speed_rpm", "depth_mm", "lower_mm", "upper_mm", "chatter_hz_q50"):
        assert same(cells(rows, key), mc[key]), key
    pt_csv = tmp_path / "pt.csv"
    cli("bands", "--model", TURNING_MODEL, "--kind", "perturbation", "--posterior", posterior,
        "--speeds", spec, "--depths", "0.05:3:30", "--out", pt_csv)
    pt = chatter.bands_perturbation(TURNING_MODEL, str(posterior), speeds_rpm=speeds,
                                    depths_mm=np.linspace(0.05, 3.0, 30))
    rows = read_csv(pt_csv)
    for key in ("speed_rpm", "depth_mm", "lower_mm", "upper_mm"):
        assert same(cells(rows, key), pt[key]), key
    # the bounds bracket the mean boundary where all three are reached
    ok = ~np.isnan(pt["lower_mm"]) & ~np.isnan(pt["upper_mm"])
    assert np.all(pt["lower_mm"][ok] <= pt["depth_mm"][ok])
    assert np.all(pt["depth_mm"][ok] <= pt["upper_mm"][ok])


def test_geometric_bands_and_plan_are_bit_identical_to_the_cli(cli, tmp_path):
    # a grid whose points are exact in both spellings (150 rpm steps)
    out = tmp_path / "geo.csv"
    cli("bands", "--model", MILLING_MODEL, "--kind", "geometric", "--speeds", "3000:12000:61",
        "--out", out)
    py = chatter.bands_geometric(MILLING_MODEL, speeds_rpm=np.linspace(3000.0, 12000.0, 61))
    rows = read_csv(out)
    for key in ("speed_rpm", "depth_mm", "lower_mm", "upper_mm", "theta_deg", "distance"):
        assert same(cells(rows, key), py[key]), key
    text = cli("plan", "--model", TURNING_MODEL, "--observations", TURNING_OBSERVATIONS,
               "--strategy", "mrr", "--paths", 20, "--seed", 4)
    assert json.loads(text) == chatter.plan(TURNING_MODEL, TURNING_OBSERVATIONS, "mrr",
                                            paths=20, seed=4)


# --- interruption ---------------------------------------------------------------------------


def _lobes():
    # about 3 s of work uninterrupted (20 000 speeds)
    return lambda: chatter.lobes(MILLING_MODEL, speeds_rpm=np.linspace(2000.0, 20000.0, 20000))


def _update():
    # iTMCMC with 20 000 samples per class: a minute and more uninterrupted
    return lambda: chatter.update(TURNING_MODEL, TURNING_OBSERVATIONS, seed=7, samples=20000,
                                  pointwise=False)


def _diagnose():
    # the data are made before the interrupt is armed, so that it lands in the diagnosis
    model, observations = chatter.synthetic_campaign("process_damping", 2.0, seed=5, cuts=8,
                                                     pole_speeds=0)
    return lambda: chatter.diagnose(model, observations, seed=2, samples=4000,
                                    validation="off", pointwise=False)


def _perturbation():
    # second-order bounds on 200 speeds x 100 depths: eigenvalue Hessians on 20 000 grid cells,
    # minutes uninterrupted
    return lambda: chatter.bands_perturbation(TURNING_MODEL, POSTERIOR_EQ34,
                                              speeds_rpm=np.linspace(6800.0, 7600.0, 200),
                                              depths_mm=np.linspace(1.5, 4.0, 100))


def _simulate():
    # 60 s of turning at 20 kHz: several seconds uninterrupted
    return lambda: chatter.simulate(TURNING_MODEL, 7000.0, 0.1, duration_s=60.0,
                                    sample_rate_hz=20000.0, seed=1)


def _oma():
    # a stable turning record of 10 s at 20 kHz, made before the interrupt is armed; its OMA
    # takes several seconds uninterrupted
    sim = chatter.simulate(TURNING_MODEL, 7000.0, 0.1, duration_s=10.0, sample_rate_hz=20000.0,
                           seed=1)
    return lambda: chatter.oma(sim["data"][:2], sim["sample_rate_hz"], speed_rpm=7000.0)


def _counters():
    return chatter._chatter._interruption_counters()


def _wait_for(condition, what, timeout_s=600.0):
    """Poll `condition` until it holds; fail naming `what` after `timeout_s` (a bound for a
    machine loaded many times over, far above the milliseconds it takes when idle)."""
    start = time.monotonic()
    while not condition():
        assert time.monotonic() - start < timeout_s, f"{what} after {timeout_s} s: {_counters()}"
        time.sleep(0.01)


def _interrupt_once_polling(done, polls_before):
    """A thread that raises Ctrl-C in the main thread as soon as the call's library has polled
    its cancellation once: the library is then inside its cancellable loop with nearly all of
    its work (seconds to minutes) ahead, while the call sees the interrupt within its 50 ms
    signal check, so the cancel lands inside the library whatever the machine's load (a timer
    can fire before the call starts or after it ends). It gives up once `done` is set."""

    def watch():
        while _counters()["observer_polls"] == polls_before:
            if done.is_set():
                return
            time.sleep(0.001)
        _thread.interrupt_main()

    thread = threading.Thread(target=watch, daemon=True)
    thread.start()
    return thread


@pytest.mark.parametrize("make", [_lobes, _update, _diagnose, _perturbation, _simulate, _oma],
                         ids=["lobes", "update", "diagnose", "perturbation", "simulate", "oma"])
def test_a_long_call_is_cancelled_inside_the_library_by_ctrl_c(make):
    """Ctrl-C raises KeyboardInterrupt from the call, and the library stopped because of it: a
    poll of its observer answered "cancelled" and its worker then returned (a library that did
    not poll the cancel would keep its worker busy for seconds to minutes, and would not count
    a cancel seen). Observed through the binding's counters, not through timing, so the test
    holds on a loaded machine."""
    call = make()
    _wait_for(lambda: _counters()["running_workers"] == 0, "a worker of an earlier call runs")
    before = _counters()
    done = threading.Event()
    watcher = _interrupt_once_polling(done, before["observer_polls"])
    try:
        with pytest.raises(KeyboardInterrupt):
            call()
    finally:
        # a watcher still waiting must not interrupt a later test
        done.set()
        watcher.join()
    # the call waits up to 5 s for its worker; on a loaded machine the library's current step
    # can take longer, so the worker's return is awaited here
    _wait_for(lambda: _counters()["running_workers"] == 0, "the cancelled worker still runs")
    assert _counters()["cancels_seen"] == before["cancels_seen"] + 1, _counters()


# --- ArviZ ----------------------------------------------------------------------------------


def test_update_inference_data_has_posterior_prior_and_pointwise_log_likelihood(seed000_update):
    az = pytest.importorskip("arviz")
    _, py = seed000_update
    idata = chatter.update_inference_data(py)
    assert {"posterior", "prior", "log_likelihood"} <= set(idata.groups())
    names = py["parameter_names"]
    assert list(idata.posterior.data_vars) == names
    first = idata.posterior[names[0]].values[0]
    assert same(first, py["samples"][:, 0])
    ll = idata.log_likelihood["y"].values[0]
    assert ll.shape[0] == len(py["samples"]) and ll.shape[1] >= 5  # every identified pole
    assert np.all(np.isfinite(ll))
    loo = az.loo(idata)
    assert np.isfinite(loo.elpd_loo)
    assert idata.attrs["selected_alpha"] == py["selected_alpha"]


def test_the_cli_netcdf_is_the_python_inference_data(seed000_update):
    az = pytest.importorskip("arviz")
    out, py = seed000_update
    cli_idata = az.from_netcdf(out / "inference_data.nc")
    idata = chatter.update_inference_data(py)
    for group in ("posterior", "prior", "log_likelihood"):
        a, b = cli_idata[group], idata[group]
        assert sorted(a.data_vars) == sorted(b.data_vars), group
        for name in b.data_vars:
            assert same(a[name].values, b[name].values), (group, name)
    assert cli_idata.attrs["selected_alpha"] == py["selected_alpha"]
    assert cli_idata.attrs["log_evidence"] == idata.attrs["log_evidence"]


def test_diagnosis_inference_data_holds_each_class_posterior():
    pytest.importorskip("arviz")
    model, observations = chatter.synthetic_campaign("process_damping", 2.0, seed=5, cuts=8,
                                                     pole_speeds=0)
    d = chatter.diagnose(model, observations, seed=2, samples=40, validation="off")
    by_class = chatter.diagnosis_inference_data(d)
    assert set(by_class) == {c["name"] for c in d["classes"]}
    for c in d["classes"]:
        idata = by_class[c["name"]]
        assert idata.attrs["log_evidence"] == c["log_evidence"]
        # prior draws and one pointwise log-likelihood column per cut (no poles here)
        assert {"posterior", "prior", "log_likelihood"} <= set(idata.groups())
        draws = len(c["posterior_samples"])
        assert idata.log_likelihood["y"].values.shape == (1, draws, len(observations["cuts"]))
        assert idata.prior[c["posterior_parameter_names"][0]].values.shape == (1, draws)
        for name, summary in c["parameters"].items():
            # the report's mean and the InferenceData's: the same samples summed two ways
            assert float(idata.posterior[name].mean()) == pytest.approx(summary["mean"],
                                                                        rel=1e-9, abs=1e-12)
