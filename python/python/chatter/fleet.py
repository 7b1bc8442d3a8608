"""Fleet runs on a Dask cluster: the campaigns of a manifest (``name,model,observations,seed``,
see the README) as one Dask task each, gathered into the table ``chatter batch`` writes.

Each task runs :func:`chatter.run_campaign` in a worker process; every campaign is seeded by its
own manifest line, so the table equals the rayon batch bit for bit whatever the cluster.
"""

from __future__ import annotations


def _campaign_line(campaign: dict, options: dict) -> str:
    from chatter import run_campaign

    row = run_campaign(
        campaign["name"], campaign["model"], campaign["observations"], campaign["seed"], **options
    )
    return row["line"]


def run_dask(manifest, client, samples: int = 120, paths: int = 300) -> str:
    """Run every campaign of ``manifest`` (a path) as one task on the Dask ``client``
    (``dask.distributed.Client``: ``Client(LocalCluster(...))`` on one machine, or
    ``Client("tcp://scheduler:8786")`` for a real cluster whose workers have ``chatter``
    installed and see the files under the same paths). Returns the table text, header first,
    rows in manifest order. ``samples`` (per effect class of the diagnosis) and ``paths``
    (sampled boundaries of the plan) as for ``chatter batch``."""
    import os

    from chatter import campaign_table, read_manifest

    campaigns = read_manifest(manifest)
    for c in campaigns:
        c["model"] = os.path.abspath(c["model"])
        c["observations"] = os.path.abspath(c["observations"])
    options = {"samples": samples, "paths": paths}
    futures = [client.submit(_campaign_line, c, options, pure=False) for c in campaigns]
    return campaign_table(client.gather(futures))
