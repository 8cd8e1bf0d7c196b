/* main.c: the bumpbake program: dispatches to a subcommand, answers
 * --help and --version. */
#include "cli.h"
#include "common.h"

#include "bumpbake.h"

#include <stdio.h>
#include <string.h>

typedef struct subcommand {
  const char *name;
  int (*run)(int argc, char **argv);
  const char *summary;
} subcommand;

static const subcommand subcommands[] = {
    {"normal", bb_cli_normal, "bake a tangent-space normal map from a height map"},
    {"bake", bb_cli_bake, "bake normal, ssbump, ao, bent normal, ... in one pass"},
    {"height2ssbump", bb_cli_height2ssbump, "drop-in for Valve's height2ssbump"},
    {"compare", bb_cli_compare, "compare two images (statistics, provenance diff)"},
    {"info", bb_cli_info, "print an image's size, format and provenance"},
    {"renderbumpflat", bb_cli_renderbumpflat, "DOOM 3's RenderBumpFlat: a flat sculpt's normal map and height"},
    {"render", bb_cli_render, "light the maps as Source does (ssbump, normal, ao; orbit)"},
    {"sheet", bb_cli_sheet, "one labelled contact sheet of every map of a bake"},
    {"normal2ssbump", bb_cli_normal2ssbump, "Valve's tool: a normal map to basis weights"},
    {"ssbump2normal", bb_cli_ssbump2normal, "the normal an ssbump (or weights) stands for"},
    {"combine", bb_cli_combine, "blend two maps, or overlay a detail map"},
    {"program", bb_cli_program, "evaluate a DOOM 3 image program (heightmap, addnormals...)"},
    {"serve", bb_cli_serve, "bake live: re-bake on save, see the maps lit in the browser"},
};

enum { SUBCOMMAND_COUNT = sizeof subcommands / sizeof subcommands[0] };

static void print_usage(FILE *f) {
  fprintf(f, "usage: bumpbake COMMAND [OPTIONS] ...\n"
             "Bakes normal maps, self-shadowed bump maps (Valve ssbump) and ambient\n"
             "occlusion from height maps.\n\ncommands:\n");
  for (int i = 0; i < SUBCOMMAND_COUNT; i++)
    fprintf(f, "  %-14s %s\n", subcommands[i].name, subcommands[i].summary);
  fprintf(f, "\n'bumpbake COMMAND --help' lists a command's options.\n"
             "  --help       print this help\n"
             "  --version    print the version\n"
             "exit codes: 0 ok, 1 failure (file or image), 2 usage error\n");
}

int main(int argc, char **argv) {
  cli_install_signal_handlers();
  if (argc < 2) {
    print_usage(stderr);
    return BB_EXIT_USAGE;
  }
  const char *name = argv[1];
  if (!strcmp(name, "--help") || !strcmp(name, "-h")) {
    print_usage(stdout);
    return BB_EXIT_OK;
  }
  if (!strcmp(name, "--version")) {
    printf("bumpbake %s\n", BB_VERSION_STRING);
    return BB_EXIT_OK;
  }
  for (int i = 0; i < SUBCOMMAND_COUNT; i++)
    if (!strcmp(name, subcommands[i].name))
      return subcommands[i].run(argc - 1, argv + 1);
  char line[512];
  snprintf(line, sizeof line, "unknown %s '%s' (see bumpbake --help)",
           name[0] == '-' ? "option" : "command", name);
  cli_error_line(line);
  return BB_EXIT_USAGE;
}
