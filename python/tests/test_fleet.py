"""The fleet batch: the same manifest on a local Dask cluster and in the rayon batch of the
command line gives the same table, bit for bit."""

import os

import pytest

import chatter

CAMPAIGNS = int(os.environ.get("CHATTER_FLEET_CAMPAIGNS", "4"))
SAMPLES, PATHS = 40, 20


def test_dask_table_equals_the_rayon_batch(cli, tmp_path):
    distributed = pytest.importorskip("dask.distributed")
    manifest = chatter.write_fleet(tmp_path / "fleet", CAMPAIGNS)
    out = tmp_path / "rayon.csv"
    cli("batch", "--manifest", manifest, "--out", out, "--samples", SAMPLES, "--paths", PATHS)
    rayon_table = out.read_text()
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                                  dashboard_address=None) as cluster:
        with distributed.Client(cluster) as client:
            dask_table = chatter.run_dask(manifest, client, samples=SAMPLES, paths=PATHS)
    assert dask_table == rayon_table
    lines = rayon_table.splitlines()
    assert lines[0] == ("name,verdict,boundary_shift_percent,next_speed_rpm,next_depth_mm,"
                        "next_p_stable,stop,error")
    assert len(lines) == CAMPAIGNS + 1
    verdicts = {"consistent", "unexplained", "parameter_error", "process_damping",
                "speed_dependent_dynamics", "extra_mode", "drift"}
    for line in lines[1:]:
        cells = line.split(",")
        assert cells[-1] == "", line  # no campaign failed
        assert cells[1] in verdicts, line
    # the in-process batch (rayon from Python) agrees too
    assert chatter.batch(manifest, samples=SAMPLES, paths=PATHS) == rayon_table


def test_the_seed_000_example_runs_and_writes_its_figures(tmp_path):
    pytest.importorskip("arviz")
    pytest.importorskip("matplotlib")
    import importlib.util
    from pathlib import Path

    path = Path(__file__).resolve().parents[1] / "examples" / "seed000.py"
    spec = importlib.util.spec_from_file_location("seed000", path)
    example = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(example)
    r = example.run(tmp_path, samples=200, seed=1, speeds=7)
    for name in ("trace.png", "bands.png", "posterior.nc"):
        assert (tmp_path / name).stat().st_size > 1000, name
    b = r["bands"]
    assert len(b["speed_rpm"]) == 7
    assert r["idata"].posterior.sizes["draw"] == len(r["result"]["samples"])
