/* installed_dirs.c: the directories `make install` chose, for the
 * installed program. The Makefile compiles this file a second time for
 * `make install`, with the install's PYTHONDIR as BB_PYTHONDIR, and links
 * that object into the program it installs; the build's own program
 * (build/bumpbake) has none and finds its source tree instead. */
#include "cluster.h"

#ifndef BB_PYTHONDIR
#define BB_PYTHONDIR ""
#endif

const char *cli_installed_python_dir(void) { return BB_PYTHONDIR; }
