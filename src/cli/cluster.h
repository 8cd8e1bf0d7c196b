/* cluster.h: `bumpbake bake --scheduler ADDRESS`, run by Python's
 * bumpbake.dask (cluster.c). */
#ifndef BB_CLI_CLUSTER_H
#define BB_CLI_CLUSTER_H

struct cli_run;

/* Runs the checked bake command r (with --scheduler) on the Dask cluster:
 * plans it here (bb_command_plan: every error the command line's, before
 * Python starts), then replaces the process with Python running
 * bumpbake.dask on the command handed over (bb_command_handover in an
 * inherited descriptor), so the same options give the same files on the
 * cluster. Python is $BUMPBAKE_PYTHON, else /usr/bin/python3 (Debian's,
 * with python3-distributed), run isolated (-I): it imports nothing from
 * the working directory, PYTHONPATH or the user's site directory. Its path
 * gets the directories of $BUMPBAKE_PYTHONPATH (absolute ones; empty
 * entries are skipped), then this source tree's python/ when this program
 * runs from one (build/bumpbake beside python/), else the install's Python
 * directory (cli_installed_python_dir). Returns only on failure: the exit
 * code, after printing why. */
int cli_cluster_exec(const struct cli_run *r);

/* Where `make install` put the Python package (its PYTHONDIR), compiled
 * into the installed program (installed_dirs.c); "" in the build's own. */
const char *cli_installed_python_dir(void);

#endif /* BB_CLI_CLUSTER_H */
