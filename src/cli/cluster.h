/* cluster.h: `bumpbake bake --scheduler ADDRESS`, run by Python's
 * bumpbake.dask (cluster.c). */
#ifndef BB_CLI_CLUSTER_H
#define BB_CLI_CLUSTER_H

/* Replaces the process with `python3 -m bumpbake.dask bake ARGS...`, args
 * the bake command's arguments as typed (argv[0] = "bake"), so the same
 * options give the same files on the cluster. Python is $BUMPBAKE_PYTHON,
 * else /usr/bin/python3 (Debian's, with python3-distributed); when this
 * program runs from a source tree (build/bumpbake beside python/), that
 * tree's python/ goes first on PYTHONPATH. Returns only on failure, with
 * BB_EXIT_FAILURE after printing why. */
int cli_cluster_exec(int argc, char **argv);

#endif /* BB_CLI_CLUSTER_H */
