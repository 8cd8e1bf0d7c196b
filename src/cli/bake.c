/* bake.c: `bumpbake bake`, every map from one height map in one pass, or a
 * batch of them (--out-dir): the options parsed into a bb_job_options, the
 * job planned, run and reported by the library (bb_job_*); this file keeps
 * the words. */
#include "bake_options.h"
#include "cli.h"
#include "cluster.h"
#include "common.h"
#include "job_json.h"
#include "json.h"
#include "options.h"
#include "progress.h"
#include "slope.h"

#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

_Static_assert(CLI_OPT_OUT_FILTERED - CLI_OPT_OUT_NORMAL + 1 == BB_OUTPUT_KIND_COUNT,
               "one --KIND option per output kind, in bb_output_kind order");

static const cli_option opt_prefix = {
    .id = CLI_OPT_OUTPUT,
    .long_name = "output",
    .short_name = 'o',
    .value_name = "PREFIX",
    .help = "write PREFIX_normal.png, PREFIX_ssbump.png and PREFIX_ao.png"};
static const cli_option opt_out_normal = {.id = CLI_OPT_OUT_NORMAL,
                                          .long_name = "normal",
                                          .value_name = "FILE",
                                          .help = "write the normal map"};
static const cli_option opt_out_weights = {.id = CLI_OPT_OUT_WEIGHTS,
                                           .long_name = "weights",
                                           .value_name = "FILE",
                                           .help =
                                               "write the basis weights (normal2ssbump)"};
static const cli_option opt_out_ssbump = {
    .id = CLI_OPT_OUT_SSBUMP,
    .long_name = "ssbump",
    .value_name = "FILE",
    .help = "write the self-shadowed bump map (traces)"};
static const cli_option opt_out_ao = {.id = CLI_OPT_OUT_AO,
                                      .long_name = "ao",
                                      .value_name = "FILE",
                                      .help = "write the ambient occlusion (traces)"};
static const cli_option opt_out_bent = {.id = CLI_OPT_OUT_BENT,
                                        .long_name = "bent",
                                        .value_name = "FILE",
                                        .help = "write the bent normal (traces)"};
static const cli_option opt_out_filtered = {.id = CLI_OPT_OUT_FILTERED,
                                            .long_name = "filtered",
                                            .value_name = "FILE",
                                            .help = "write the smoothed height"};
static const cli_option opt_slices = {
    .id = CLI_OPT_SLICES,
    .long_name = "slices",
    .value_name = "A",
    .default_text = "from --rays",
    .range_text = "1..256",
    .help = "azimuth slices, each integrated exactly above its horizon (overrides --rays)"};
static const cli_option opt_out_dir = {
    .id = CLI_OPT_OUT_DIR,
    .long_name = "out-dir",
    .value_name = "DIR",
    .help = "a batch: bake every HEIGHT (files, or directories of images) into DIR"};
static const cli_option opt_name = {
    .id = CLI_OPT_NAME,
    .long_name = "name",
    .value_name = "TEMPLATE",
    .default_text = BB_JOB_DEFAULT_NAME,
    .range_text = "{stem} {kind} {ext}",
    .help = "a batch's file names: the input's stem, the map, the input's extension"};
static const cli_option opt_maps = {
    .id = CLI_OPT_MAPS,
    .long_name = "maps",
    .value_name = "LIST",
    .default_text = "normal,ssbump,ao",
    .range_text = "normal weights ssbump ao bent filtered",
    .help = "the maps a batch writes, comma-separated"};
static const cli_option opt_keep_going = {
    .id = CLI_OPT_KEEP_GOING,
    .long_name = "keep-going",
    .help = "a batch goes on after an input fails (and exits 1 at the end)"};
static const cli_option opt_force = {
    .id = CLI_OPT_FORCE,
    .long_name = "force",
    .help = "a batch bakes inputs whose outputs are up to date, too"};
static const cli_option opt_depfile = {
    .id = CLI_OPT_DEPFILE,
    .long_name = "depfile",
    .value_name = "FILE",
    .help = "write a Make/Ninja depfile: the outputs depend on the input (and --basis FILE)"};
static const cli_option opt_json = {
    .id = CLI_OPT_JSON,
    .long_name = "json",
    .default_text = "off",
    .help = "print one JSON line describing the bake on stdout"};
static const cli_option opt_scheduler = {
    .id = CLI_OPT_SCHEDULER,
    .long_name = "scheduler",
    .value_name = "ADDRESS",
    .help = "bake on the Dask cluster of this scheduler (tcp://host:8786): a batch's inputs "
            "on its workers, a single map's trace split over them (docs/cluster.md)"};
static const cli_option opt_quiet = {.id = CLI_OPT_QUIET,
                                     .long_name = "quiet",
                                     .short_name = 'q',
                                     .help = "no progress bar, no list of files written"};

static const cli_option opt_bounce = {
    .id = CLI_OPT_BOUNCE,
    .long_name = "bounce",
    .value_name = "RHO",
    .default_text = "0 (none; 1 with --bounce-albedo)",
    .range_text = "0..1",
    .help = "inter-reflection: ao, ssbump and bent include the light the relief "
            "reflects, albedo RHO (docs/commands/bake.md)"};
static const cli_option opt_bounces = {
    .id = CLI_OPT_BOUNCES,
    .long_name = "bounces",
    .value_name = "N",
    .default_text = "0 (until converged)",
    .range_text = "0..64",
    .help = "bounces of reflected light to follow"};
static const cli_option opt_bounce_albedo = {
    .id = CLI_OPT_BOUNCE_ALBEDO,
    .long_name = "bounce-albedo",
    .value_name = "FILE",
    .help = "albedo map (grey; RGB: luma) of the height's size, times RHO"};
static const cli_option opt_brightness = {
    .id = CLI_OPT_BRIGHTNESS,
    .long_name = "brightness",
    .value_name = "FILE",
    .help = "brightness map (grey; RGB: luma) multiplying ssbump and weights "
            "(a texel over 1 is scaled down whole)"};

/* The bake's parameters and its outputs one by one: bake's and serve's. */
#define BAKE_PARAMETER_ROWS                                                              \
  &cli_opt_scale, &cli_opt_rays, &opt_slices, &cli_opt_filter_radius,                    \
      &cli_opt_filter_threshold, &cli_opt_bias, &cli_opt_power, &cli_opt_basis,          \
      &cli_opt_normal_filter, &cli_opt_normal_y, &cli_opt_threads, &cli_opt_clamp,       \
      &cli_opt_channel, &cli_opt_depth, &cli_opt_mips, &opt_bounce, &opt_bounces,        \
      &opt_bounce_albedo, &opt_brightness, &opt_out_normal, &opt_out_weights,            \
      &opt_out_ssbump, &opt_out_ao, &opt_out_bent, &opt_out_filtered

static const cli_option *const bake_options[] = {
    BAKE_PARAMETER_ROWS,  &cli_opt_slope,     &cli_opt_slope_lit, &opt_prefix,
    &opt_out_dir,      &opt_maps,          &opt_name,         &opt_keep_going,
    &opt_force,        &opt_depfile,       &opt_json,         &opt_quiet,
    CLI_TEXTURE_OPTIONS, &cli_opt_vmt,     &cli_opt_materials, &cli_opt_basetexture,
    &opt_scheduler,    &cli_opt_help,
};

static const cli_command bake_command = {
    "bake",
    "HEIGHT --scale S [OPTIONS] (-o PREFIX | --normal FILE | --ssbump FILE | ... | "
    "--out-dir DIR)",
    "Bakes the requested maps from HEIGHT in one pass; tracing runs only when\n"
    "ssbump, ao or bent is asked for. Tracing finds each texel's exact horizon\n"
    "in each azimuth slice and integrates the slice above it exactly; what is\n"
    "left is azimuth sampling. Cost and mean |error| against converged truth\n"
    "(rock06, 1024 x 1024 at scale 128, 2 cores; error on its 256 x 256 downsample):\n"
    "  budget       slices   trace     ao      ssbump\n"
    "  64 rays         8     ~0.4 s   0.0015   0.0030\n"
    "  256 rays       16     ~0.7 s   0.0004   0.0010   (the default)\n"
    "  1024 rays      32     ~2.6 s   0.0001   0.0004\n"
    "With --clamp the trace takes 2.3 to 3.4 times as long. See\n"
    "docs/performance.md and docs/accuracy.md.\n"
    "\n"
    "Batches: bumpbake bake HEIGHT|DIR... --scale S --out-dir DIR [--maps LIST]\n"
    "bakes every HEIGHT (a directory: the images in it, sorted, not below it)\n"
    "in one process into DIR/--name, and skips an input whose outputs are\n"
    "up to date: their provenance names the same input bytes, parameters\n"
    "and bumpbake version (--force bakes anyway).",
    bake_options,
    (int)(sizeof bake_options / sizeof bake_options[0]),
    cli_settings_init,
};

typedef struct bake_args {
  cli_settings settings;
  bb_job_options job;
  cli_slope_args slope; /* --slope FILE, --lit AZ,EL */
  const char *maps;     /* --maps LIST as given */
  int json, quiet;
  const char *scheduler; /* --scheduler ADDRESS, or NULL */
} bake_args;

int cli_bake_parameter(const char *command, cli_settings *s, bb_job_options *job,
                       const cli_option *opt, const char *arg) {
  if (opt->id >= CLI_OPT_OUT_NORMAL && opt->id <= CLI_OPT_OUT_FILTERED) {
    job->paths[opt->id - CLI_OPT_OUT_NORMAL] = arg;
    return 0;
  }
  switch (opt->id) {
  case CLI_OPT_OUTPUT: job->prefix = arg; return 0;
  case CLI_OPT_SLICES: return cli_settings_apply_slices(command, s, arg);
  case CLI_OPT_BOUNCE:
    return cli_parse_double(command, "--bounce", arg, 0.0, 0, 1.0, &s->bake.bounce_albedo);
  case CLI_OPT_BOUNCES:
    return cli_parse_int(command, "--bounces", arg, 0, BB_MAX_BOUNCES, &s->bake.bounces);
  case CLI_OPT_BOUNCE_ALBEDO: job->bounce_albedo_file = arg; return 0;
  case CLI_OPT_BRIGHTNESS: job->brightness_file = arg; return 0;
  default: break;
  }
  return cli_settings_apply(command, s, opt, arg);
}

void cli_bake_settings_to_job(const cli_settings *s, bb_job_options *job) {
  job->bake = s->bake;
  job->channel = s->channel;
  job->depth = s->depth;
  job->mips = s->mips;
  job->texture = s->texture;
  job->basis_file = s->basis_file;
}

const cli_option *const cli_bake_parameter_rows[] = {
    BAKE_PARAMETER_ROWS, &opt_prefix, CLI_TEXTURE_OPTIONS,
};
const int cli_bake_parameter_row_count =
    (int)(sizeof cli_bake_parameter_rows / sizeof cli_bake_parameter_rows[0]);

static int bake_option(void *ctx, const cli_option *opt, const char *arg) {
  bake_args *a = ctx;
  if (cli_slope_owns(opt))
    return cli_slope_option(bake_command.name, &a->slope, opt, arg);
  switch (opt->id) {
  case CLI_OPT_OUT_DIR: a->job.out_dir = arg; return 0;
  case CLI_OPT_NAME: a->job.name_template = arg; return 0;
  case CLI_OPT_MAPS: a->maps = arg; return 0;
  case CLI_OPT_KEEP_GOING: a->job.keep_going = 1; return 0;
  case CLI_OPT_FORCE: a->job.force = 1; return 0;
  case CLI_OPT_DEPFILE: a->job.depfile = arg; return 0;
  case CLI_OPT_JSON: a->json = 1; return 0;
  case CLI_OPT_QUIET: a->quiet = 1; return 0;
  case CLI_OPT_SCHEDULER: a->scheduler = arg; return 0;
  case CLI_OPT_VMT: a->job.vmt = arg; return 0;
  case CLI_OPT_MATERIALS: a->job.vmt_materials = arg; return 0;
  case CLI_OPT_BASETEXTURE: a->job.vmt_basetexture = arg; return 0;
  default: break;
  }
  return cli_bake_parameter(bake_command.name, &a->settings, &a->job, opt, arg);
}

/* --maps LIST: the library's map names, comma-separated. */
static int parse_maps(const char *list, unsigned *maps) {
  *maps = 0;
  for (const char *s = list; *s;) {
    size_t n = strcspn(s, ",");
    char name[32];
    snprintf(name, sizeof name, "%.*s", (int)(n < sizeof name ? n : sizeof name - 1), s);
    bb_output_kind kind;
    bb_error err = {{0}};
    if (n >= sizeof name || bb_output_kind_parse(name, &kind, &err) != BB_OK) {
      char names[128] = "";
      for (int k = 0; k < BB_OUTPUT_KIND_COUNT; k++)
        snprintf(names + strlen(names), sizeof names - strlen(names), "%s%s", k ? ", " : "",
                 bb_output_kind_get((bb_output_kind)k)->name);
      return cli_usage_error(bake_command.name, "--maps: unknown map '%.*s' (one of %s)",
                             (int)n, s, names);
    }
    *maps |= BB_OUTPUT_BIT(kind);
    s += n + (s[n] == ',');
  }
  return *maps ? 0 : cli_usage_error(bake_command.name, "--maps: no map named");
}

/* Options that only a batch uses are usage errors without --out-dir. */
static int check_single(const bake_args *a) {
  const char *batch_only = a->job.name_template ? "--name"
                           : a->maps           ? "--maps"
                           : a->job.keep_going ? "--keep-going"
                           : a->job.force      ? "--force"
                                               : NULL;
  if (!batch_only)
    return 0;
  return cli_usage_error(bake_command.name, "%s is for batches: give --out-dir DIR",
                         batch_only);
}

/* Parses and checks the command line into a->job; *first receives the
 * index of the first HEIGHT. */
static int bake_parse(int argc, char **argv, bake_args *a, int *first) {
  int rc = cli_parse_options(&bake_command, argc, argv, bake_option, a, first);
  if (!rc && !a->job.out_dir)
    rc = check_single(a);
  if (!rc && argc - *first > 1 && !a->job.out_dir)
    rc = cli_usage_error(bake_command.name, "several HEIGHT files need --out-dir DIR");
  if (!rc)
    rc = cli_expect_positionals(&bake_command, argc, argv, *first,
                                a->job.out_dir && argc - *first > 1 ? argc - *first : 1,
                                "HEIGHT");
  if (!rc && !a->settings.scale_given)
    rc = cli_usage_error(bake_command.name,
                         "--scale is required (texels of displacement per unit of height)");
  if (!rc && a->maps)
    rc = parse_maps(a->maps, &a->job.maps);
  if (rc)
    return rc;
  cli_bake_settings_to_job(&a->settings, &a->job);
  a->job.slope_path = a->slope.path;
  a->job.slope_lit = a->slope.lit;
  a->job.slope_lit_azimuth = a->slope.azimuth;
  a->job.slope_lit_elevation = a->slope.elevation;
  a->job.force |= !a->job.out_dir; /* a single bake always bakes */
  return 0;
}

/* ------------------------------------------------------------------ print */

/* A batch's line for an input that was not baked: up to date or failed. */
static void print_short_json(const bb_job_report *r) {
  cli_json j = {stdout, 0};
  cli_json_open(&j, NULL, '{');
  cli_json_string(&j, "input", r->input);
  cli_json_string(&j, "status", r->outcome == BB_JOB_CURRENT ? "up to date" : "failed");
  if (r->outcome == BB_JOB_FAILED)
    cli_json_int(&j, "exit_code", BB_EXIT_FAILURE);
  cli_json_open(&j, "outputs", '[');
  for (int i = 0; i < r->output_count; i++) {
    cli_json_open(&j, NULL, '{');
    cli_json_string(&j, "kind", r->outputs[i].kind);
    cli_json_string(&j, "path", r->outputs[i].path);
    cli_json_close(&j, '}');
  }
  cli_json_close(&j, ']');
  cli_json_close(&j, '}');
  fputc('\n', stdout);
}

/* What the command line says of one input once it ran. */
typedef struct printer {
  const bake_args *a;
  int batch;
  int counts[5]; /* by bb_job_outcome */
  cli_progress *progress; /* its bar is cleared before anything is printed */
} printer;

static void print_report(void *user, const bb_job_report *r) {
  printer *p = user;
  cli_progress_finish(p->progress);
  p->counts[r->outcome]++;
  if (r->outcome == BB_JOB_FAILED)
    cli_error_line(r->error.message[0] ? r->error.message : bb_status_name(r->status));
  if (r->outcome == BB_JOB_NOT_RUN)
    return;
  if (p->a->json) {
    if (r->outcome == BB_JOB_BAKED)
      cli_job_json(&p->a->job.bake, r, p->batch ? "baked" : NULL);
    else if (p->batch)
      print_short_json(r);
  } else if (!p->a->quiet) {
    const char *verb = r->outcome == BB_JOB_BAKED     ? "wrote"
                       : r->outcome == BB_JOB_CURRENT ? "up to date"
                                                      : NULL;
    for (int i = 0; verb && i < r->output_count; i++)
      cli_printf_line("%s %s %s", verb, r->outputs[i].kind, r->outputs[i].path);
  }
  fflush(stdout);
}

static void print_summary(const bake_args *a, const printer *p, int files) {
  if (a->json) {
    cli_json j = {stdout, 0};
    cli_json_open(&j, NULL, '{');
    cli_json_open(&j, "summary", '{');
    cli_json_int(&j, "files", files);
    cli_json_int(&j, "baked", p->counts[BB_JOB_BAKED]);
    cli_json_int(&j, "up_to_date", p->counts[BB_JOB_CURRENT]);
    cli_json_int(&j, "failed", p->counts[BB_JOB_FAILED]);
    cli_json_int(&j, "not_run", p->counts[BB_JOB_NOT_RUN]);
    cli_json_close(&j, '}');
    cli_json_close(&j, '}');
    fputc('\n', stdout);
  } else if (!a->quiet) {
    printf("%s: %d file%s: %d baked, %d up to date, %d failed", bake_command.name, files,
           files == 1 ? "" : "s", p->counts[BB_JOB_BAKED], p->counts[BB_JOB_CURRENT],
           p->counts[BB_JOB_FAILED]);
    if (p->counts[BB_JOB_NOT_RUN])
      printf(", %d not run (stopped at the first failure; --keep-going goes on)",
             p->counts[BB_JOB_NOT_RUN]);
    fputc('\n', stdout);
  }
}

/* ------------------------------------------------------------------- run */

/* "OPTIONS" of "bumpbake bake INPUT OPTIONS": the options as typed (getopt
 * has moved every positional after them), for a batch's provenance. */
static char *options_text(char **argv, int first) {
  size_t len = 1;
  for (int i = 1; i < first; i++)
    len += strlen(argv[i]) + 1;
  char *text = malloc(len);
  if (!text)
    return NULL;
  text[0] = '\0';
  for (int i = 1; i < first; i++) {
    if (i > 1)
      strcat(text, " ");
    strcat(text, argv[i]);
  }
  return text;
}

static int bake_run(bake_args *a, const char *command_line, char **argv, int argc, int first) {
  char *options = a->job.out_dir ? options_text(argv, first) : NULL;
  if (a->job.out_dir && !options) {
    cli_error_line("out of memory");
    return BB_EXIT_FAILURE;
  }
  a->job.command = a->job.out_dir ? NULL : command_line;
  a->job.command_options = options;
  a->job.note = cli_note;
  bb_job *job = NULL;
  bb_error err = {{0}};
  bb_status st = bb_job_plan((const char *const *)argv + first, argc - first, &a->job, &job,
                             &err);
  free(options);
  if (st != BB_OK)
    return cli_library_error(bake_command.name, st, &err);
  cli_progress progress;
  printer p = {a, a->job.out_dir != NULL, {0}, &progress};
  cli_progress_start(&progress, "bake", a->quiet);
  st = bb_job_run(job, cli_progress_fn(&progress), &progress, print_report, &p, &err);
  cli_progress_finish(&progress);
  int rc = BB_EXIT_OK;
  if (st != BB_OK) {
    rc = BB_EXIT_FAILURE;
    /* An input's failure was printed with its report; what is left is the
     * depfile's. */
    if (!p.counts[BB_JOB_FAILED])
      cli_error_line(err.message);
  }
  if (p.batch)
    print_summary(a, &p, bb_job_count(job));
  bb_job_free(job);
  return rc;
}

int bb_cli_bake(int argc, char **argv) {
  char *command_line = cli_command_line(argc, argv); /* before getopt permutes argv */
  if (!command_line)
    return BB_EXIT_FAILURE;
  bake_args a;
  memset(&a, 0, sizeof a);
  cli_settings_init(&a.settings);
  bb_job_options_init(&a.job);
  int first = 0;
  /* the arguments as typed, for --scheduler (getopt permutes argv) */
  char **typed = malloc(((size_t)argc + 1) * sizeof *typed);
  if (!typed) {
    free(command_line);
    return BB_EXIT_FAILURE;
  }
  memcpy(typed, argv, (size_t)argc * sizeof *typed);
  int rc = bake_parse(argc, argv, &a, &first);
  if (rc < 0)
    rc = BB_EXIT_OK; /* --help */
  else if (rc == 0 && a.scheduler)
    rc = cli_cluster_exec(argc, typed); /* returns only on failure */
  else if (rc == 0)
    rc = bake_run(&a, command_line, argv, argc, first);
  free(typed);
  free(command_line);
  return rc;
}
