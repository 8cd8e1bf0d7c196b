#!/usr/bin/python3
"""bench_cluster.py: the Dask halves of tools/bench_cluster.sh, on a
LocalCluster of WORKERS worker processes of one thread each.

    bench_cluster.py batch DIR OUT ROUNDS   bake_files of DIR's maps into OUT,
                                            --force, ROUNDS times; one JSON line
    bench_cluster.py big MAP PREFIX         bake_big of MAP into PREFIX_ssbump.png
                                            and PREFIX_ao.png; one JSON line:
                                            seconds, peak memory of every
                                            process, bytes moved

Options as tools/bench_cluster.sh bakes: --scale 64 and bake's defaults.
"""

import json
import resource
import sys
import time

import distributed

import bumpbake
import bumpbake.dask


def peak_kib():
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss


def cluster(workers):
    return distributed.LocalCluster(n_workers=workers, threads_per_worker=1, processes=True,
                                    dashboard_address=None, silence_logs=40)


def batch(directory, out, rounds, workers=2):
    t0 = time.monotonic()
    with cluster(workers) as c, distributed.Client(c) as client:
        client.wait_for_workers(workers)
        start = time.monotonic() - t0
        seconds = []
        for _ in range(rounds):
            t = time.monotonic()
            reports = bumpbake.dask.bake_files(directory, out, client=client, scale=64,
                                               force=True, notes="ignore")
            seconds.append(time.monotonic() - t)
            assert all(r.status == "baked" for r in reports), "a bake failed"
        t = time.monotonic()
        again = bumpbake.dask.bake_files(directory, out, client=client, scale=64,
                                         notes="ignore")
        rerun = time.monotonic() - t
        assert all(r.status == "up to date" for r in again)
    # the CLI batch that records the same command: bake DIR OPTIONS
    options = bumpbake.BakeJob(directory, out, scale=64, force=True).command_text(0).split()[3:]
    print(json.dumps({"files": len(reports), "seconds": seconds, "cluster_start_s": start,
                      "rerun_s": rerun, "workers": workers, "options": options}))


def big(path, prefix, workers=2):
    """bake_big of path into PREFIX_ssbump.png and PREFIX_ao.png, which
    record `bumpbake bake PATH --scale 64 --ssbump ... --ao ...`."""
    with cluster(workers) as c, distributed.Client(c) as client:
        client.wait_for_workers(workers)
        before = client.run(peak_kib)
        t = time.monotonic()
        report = bumpbake.dask.bake_big(path, {"ssbump": prefix + "_ssbump.png",
                                               "ao": prefix + "_ao.png"},
                                        client=client, scale=64)
        seconds = time.monotonic() - t
        workers_peak = client.run(peak_kib)
    print(json.dumps({"seconds": seconds, "report_seconds": report.seconds,
                      "cluster": report.cluster, "worker_peak_kib": workers_peak,
                      "worker_peak_before_kib": before, "client_peak_kib": peak_kib()}))


if __name__ == "__main__":
    what = sys.argv[1]
    if what == "batch":
        batch(sys.argv[2], sys.argv[3], int(sys.argv[4]))
    elif what == "big":
        big(sys.argv[2], sys.argv[3])
    else:
        sys.exit(f"usage: {sys.argv[0]} batch DIR OUT ROUNDS | big MAP PREFIX")
