"""A fleet of synthetic machine-tool campaigns on a local Dask cluster and in the rayon batch,
with the throughput of each (campaigns per minute per core).

    python python/examples/fleet.py OUT_DIR [--campaigns 50] [--workers 2] [--chatter target/release/chatter]
"""

from __future__ import annotations

import argparse
import os
import subprocess
import time

import chatter

SAMPLES, PATHS = 40, 20


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("out_dir")
    p.add_argument("--campaigns", type=int, default=50)
    p.add_argument("--workers", type=int, default=os.cpu_count() or 1)
    p.add_argument("--chatter", default=None, help="chatter binary for the rayon batch")
    a = p.parse_args()
    manifest = chatter.write_fleet(a.out_dir, a.campaigns)
    from dask.distributed import Client, LocalCluster

    with LocalCluster(n_workers=a.workers, threads_per_worker=1, dashboard_address=None) as c:
        with Client(c) as client:
            t = time.perf_counter()
            dask_table = chatter.run_dask(manifest, client, samples=SAMPLES, paths=PATHS)
            dask_s = time.perf_counter() - t
    rate = a.campaigns / (dask_s / 60) / a.workers
    print(f"dask: {a.campaigns} campaigns in {dask_s:.1f} s on {a.workers} workers: "
          f"{rate:.2f} campaigns per minute per core")
    if a.chatter:
        out = os.path.join(a.out_dir, "rayon.csv")
        t = time.perf_counter()
        subprocess.run([a.chatter, "--quiet", "batch", "--manifest", str(manifest), "--out", out,
                        "--samples", str(SAMPLES), "--paths", str(PATHS)], check=True)
        rayon_s = time.perf_counter() - t
        cores = os.cpu_count() or 1
        print(f"rayon: {rayon_s:.1f} s on {cores} cores: "
              f"{a.campaigns / (rayon_s / 60) / cores:.2f} campaigns per minute per core")
        print("tables equal:", open(out).read() == dask_table)
    print(dask_table)


if __name__ == "__main__":
    main()
