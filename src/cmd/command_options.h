/* command_options.h: where a command's options land, typed (not public:
 * clients read them by name, bb_command_value, or the bake's as the stage
 * API's struct, bb__command_job_options), so a command or an option added
 * changes no public struct. */
#ifndef BB_CMD_COMMAND_OPTIONS_H
#define BB_CMD_COMMAND_OPTIONS_H

#include "bumpbake.h"
#include "job/job_options.h"  /* bb_job_options */
#include "mesh/mesh_internal.h" /* bb_renderbump_options */
#include "render/render_internal.h" /* bb_render_options */

/* Every option of every command lands here, typed: the command's own
 * structs (a bake's bb_job_options, a render's bb_render_options...) and
 * what has no struct of its own yet. A command uses the fields its options
 * name. Strings point into the bb_command, which owns them. */
typedef struct bb_command_options {
  bb_job_options job;           /* bake, normal, height2ssbump; the bake of render's
                                   and sheet's HEIGHT; depth, mips and texture settings
                                   of every command writing maps */
  const char *output;           /* -o of the commands writing one named file (render,
                                   sheet, combine, ...: the default filled in by
                                   bb_command_check where the command has one) */
  bb_render_options render;     /* render's picture; sheet's lit panel */
  const char *render_maps[BB_MAP_KIND_COUNT]; /* render --normal, --ssbump, --ao,
                                   --bent, --slope (by bb_map_kind) */
  const char *albedo;           /* render --albedo */
  int render_compare;           /* render --compare */
  int orbit;                    /* render --orbit: frames, 0: one picture */
  int maps_normal_y_up;         /* --normal-y up of render, normal2ssbump, combine
                                   (the maps read), ssbump2normal and renderbumpflat
                                   (the map written) */
  int panel_size;               /* sheet --panel-size */
  bb_compare_limits limits;     /* compare */
  const char *diff;             /* compare --diff */
  const char *limit_rules;      /* check --limits: "KIND|PATTERN: -fail T ...; ..." */
  int check_bake;               /* check --bake: the inputs after GOLDEN are heights */
  int update;                   /* check --update */
  const char *junit, *html;     /* check --junit FILE, --html DIR */
  bb_renderbump_options renderbump; /* renderbumpflat */
  const char *height_output;    /* renderbumpflat --height */
  bb_map_kind map_kind;         /* combine --kind */
  bb_map_kind ssbump_kind;      /* ssbump2normal --kind: BB_MAP_SSBUMP or _WEIGHTS */
  double mix;                   /* combine --mix */
  const char *mask;             /* combine --mask */
  int detail;                   /* combine --detail */
  const char *brightness;       /* combine --brightness */
  const char *base_dir;         /* program --base */
  int allow_outside_base;       /* program --allow-outside-base */
  int json, quiet;              /* how a command-line client prints */
  const char *scheduler;        /* bake --scheduler: a Dask scheduler's address */
} bb_command_options;

/* The options as set (defaults elsewhere); owned by command. */
const bb_command_options *bb__command_options_of(const bb_command *command);

#endif /* BB_CMD_COMMAND_OPTIONS_H */
