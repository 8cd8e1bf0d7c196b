#!/usr/bin/python3
"""bench_cluster.py: the Dask halves of tools/bench_cluster.sh, on a
LocalCluster of WORKERS worker processes of one thread each.

    bench_cluster.py batch DIR OUT ROUNDS   bake_files of DIR's maps into OUT,
                                            --force, ROUNDS times; one JSON line
    bench_cluster.py big MAP PREFIX         bake_big of MAP into PREFIX_ssbump.png
                                            and PREFIX_ao.png; one JSON line:
                                            seconds, peak memory of every
                                            process, bytes moved
    bench_cluster.py phases MAP PREFIX      the same bake, and where its time
                                            went: each process's CPU seconds
                                            in each phase (sampled every
                                            0.1 s), the horizon tasks'
                                            seconds on each worker; one JSON
                                            line

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


class _Sampler:
    """(monotonic seconds, CPU seconds of this process) every 0.1 s, on a
    thread of the process it is started in."""

    def __init__(self):
        import threading
        self.samples, self.stop = [], threading.Event()
        self.thread = threading.Thread(target=self._run, daemon=True)
        self.thread.start()

    def _run(self):
        import os
        while True:
            t = os.times()
            self.samples.append((time.monotonic(), t.user + t.system))
            if self.stop.wait(0.1):
                return


def _sampler_start(dask_worker):
    dask_worker.bench_sampler = _Sampler()


def _sampler_end(dask_worker):
    sampler = dask_worker.bench_sampler
    sampler.stop.set()
    sampler.thread.join()
    sampler._run()  # one last sample
    return sampler.samples


def _cpu_between(samples, a, b):
    """CPU seconds of a process between monotonic times a and b (linear
    between the samples)."""
    def at(t):
        prev = samples[0]
        for s in samples:
            if s[0] >= t:
                if s[0] == prev[0]:
                    return s[1]
                return prev[1] + (s[1] - prev[1]) * (t - prev[0]) / (s[0] - prev[0])
            prev = s
        return samples[-1][1]
    return at(b) - at(a)


def phases(path, prefix, workers=2):
    """bake_big as big() does, with each process's CPU sampled: the CPU of
    the client (with the scheduler), the driver's worker and the other
    worker in each phase: plan and submit (until the driver starts), the
    driver's read, smoothing and pyramid (until its trace starts), the
    trace, derive and write (until the driver ends), the result's way
    back."""
    with cluster(workers) as c, distributed.Client(c) as client:
        client.wait_for_workers(workers)
        client.run(_sampler_start)
        here = _Sampler()
        offset = time.time() - time.monotonic()
        with distributed.get_task_stream(client) as stream:
            t = time.monotonic()
            report = bumpbake.dask.bake_big(path, {"ssbump": prefix + "_ssbump.png",
                                                   "ao": prefix + "_ao.png"},
                                            client=client, scale=64)
            end = time.monotonic()
        samples = client.run(_sampler_end)
        samples["client"] = _sampler_end(type("Here", (), {"bench_sampler": here}))
        tasks = {}
        drive_start = None
        for rec in stream.data:
            for ss in rec["startstops"]:
                if ss["action"] != "compute":
                    continue
                if rec["key"].startswith("bumpbake-big-"):
                    drive_start = ss["start"] - offset
                elif rec["key"].startswith("bumpbake-horizons-"):
                    tasks.setdefault(rec["worker"], []).append(ss["stop"] - ss["start"])
    st = report.cluster
    driver = st["driver"]
    marks = [("plan and submit", t), ("read, smooth, pyramid", drive_start),
             ("trace", drive_start + st["seconds_before_trace"]),
             ("derive, write", drive_start + st["seconds_before_trace"] + st["seconds_trace"]),
             ("result back", drive_start + st["seconds_driver"]), ("end", end)]
    names = {driver: "driver's worker", "client": "client and scheduler"}
    for w in samples:
        names.setdefault(w, "other worker")
    table = {}
    for (name, a), (_, b) in zip(marks, marks[1:]):
        table[name] = {"seconds": round(b - a, 3)}
        for w, s in samples.items():
            table[name][names[w]] = round(_cpu_between(s, a, b), 3)
    total = {names[w]: round(_cpu_between(s, t, end), 3) for w, s in samples.items()}
    print(json.dumps({"seconds": end - t, "report_seconds": report.seconds, "cluster": st,
                      "phases": table, "cpu_seconds": total,
                      "horizon_tasks": {names[w]: {"count": len(d), "seconds": round(sum(d), 3)}
                                        for w, d in tasks.items()}}))


if __name__ == "__main__":
    what = sys.argv[1]
    if what == "batch":
        batch(sys.argv[2], sys.argv[3], int(sys.argv[4]))
    elif what == "big":
        big(sys.argv[2], sys.argv[3])
    elif what == "phases":
        phases(sys.argv[2], sys.argv[3])
    else:
        sys.exit(f"usage: {sys.argv[0]} batch DIR OUT ROUNDS | big MAP PREFIX | phases MAP PREFIX")
