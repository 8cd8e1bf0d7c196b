"""bumpbake on a Dask cluster (Debian's python3-distributed): batches and
big maps spread over many machines, the bytes one machine writes.

    from distributed import Client
    import bumpbake.dask
    client = Client("tcp://scheduler:8786")
    reports = bumpbake.dask.bake_files("heights/", "maps/", client=client, scale=64)
    report = bumpbake.dask.bake_big("terrain_16k.png", prefix="maps/terrain", client=client,
                                    scale=64)

bake_files: a batch planned on the client, its stale inputs baked on the
workers in chunks. check_files: a golden suite (bumpbake.check with heights) baked and
compared on the workers, reported by the client. bake_big: one map whose trace (the sweeps of its
slices) is split over the workers and added up in the single machine's
order, so its files are a single bake's bit for bit. Workers open the
client's paths (shared storage). `bumpbake bake ... --scheduler ADDRESS`
is the same from the command line: the C program checks and plans the
command and hands it to _command, which runs it with these.
docs/cluster.md says how to start a cluster and what each worker holds.
"""

try:
    import distributed  # noqa: F401
except ImportError as e:
    raise ModuleNotFoundError(
        f"bumpbake.dask needs Dask's distributed ({e}): install Debian's python3-distributed "
        "and python3-dask (make deps)", name=e.name) from None

from ._batch import bake_files
from ._big import bake_big
from ._check import check_files
from ._connect import ClusterLost

__all__ = ["ClusterLost", "bake_big", "bake_files", "check_files"]
