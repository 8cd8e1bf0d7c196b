/* serve.c: `bumpbake serve`, a bake seen live: the height baked with
 * bake's options, watched, re-baked on every save, and shown lit in the
 * browser (src/cli/serve/). This file keeps the command line's words. */
#include "bake_options.h"
#include "cli.h"
#include "common.h"
#include "options.h"
#include "serve/serve.h"

#include <arpa/inet.h>
#include <limits.h>
#include <netinet/in.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

/* The port serve listens on unless told. */
#define SERVE_DEFAULT_PORT 8077

/* serve's own options: ids past every shared one. */
enum { SERVE_OPT_PORT = 1000, SERVE_OPT_ADDRESS };

static const cli_option opt_port = {
    .id = SERVE_OPT_PORT,
    .long_name = "port",
    .value_name = "N",
    .default_text = "8077",
    .range_text = "0..65535",
    .help = "the port to listen on, 0 = any free one (the URL printed says which)"};
static const cli_option opt_address = {
    .id = SERVE_OPT_ADDRESS,
    .long_name = "address",
    .value_name = "A",
    .default_text = "127.0.0.1",
    .help = "listen on this IPv4 or IPv6 address instead: the URL then carries a "
            "random token every request needs"};
static const cli_option opt_quiet = {.id = CLI_OPT_QUIET,
                                     .long_name = "quiet",
                                     .short_name = 'q',
                                     .help = "print only the URL, not each bake"};

typedef struct serve_args {
  cli_settings settings;
  bb_job_options job;
  int port, quiet;
  const char *address;
} serve_args;

static int serve_option(void *ctx, const cli_option *opt, const char *arg) {
  serve_args *a = ctx;
  switch (opt->id) {
  case SERVE_OPT_PORT: return cli_parse_int("serve", "--port", arg, 0, 65535, &a->port);
  case SERVE_OPT_ADDRESS: {
    unsigned char any[sizeof(struct in6_addr)];
    if (inet_pton(AF_INET, arg, any) != 1 && inet_pton(AF_INET6, arg, any) != 1)
      return cli_usage_error("serve", "--address: '%s' is not an IPv4 or IPv6 address", arg);
    a->address = arg;
    return 0;
  }
  case CLI_OPT_QUIET: a->quiet = 1; return 0;
  default: break;
  }
  return cli_bake_parameter("serve", &a->settings, &a->job, opt, arg);
}

/* The write action's files: as bake's -o PREFIX names them, spelled out
 * one by one (--normal P_normal.png ...) so that the command line the page
 * shows is the whole job; PREFIX defaults to HEIGHT without its extension. */
static int name_outputs(bb_job_options *job, const char *height) {
  char prefix[PATH_MAX];
  if (job->prefix) {
    snprintf(prefix, sizeof prefix, "%s", job->prefix);
  } else {
    snprintf(prefix, sizeof prefix, "%s", height);
    char *dot = strrchr(prefix, '.'), *slash = strrchr(prefix, '/');
    if (dot && (!slash || dot > slash + 1))
      *dot = '\0';
  }
  int named = 0;
  for (int k = 0; k < BB_OUTPUT_KIND_COUNT; k++)
    named |= job->paths[k] != NULL;
  if (named && !job->prefix)
    return 0; /* the outputs the command line named, and only those */
  for (int k = 0; k < BB_OUTPUT_KIND_COUNT; k++) {
    if (!(BB_JOB_DEFAULT_MAPS & BB_OUTPUT_BIT(k)) || job->paths[k])
      continue;
    size_t n = strlen(prefix) + 32;
    char *path = malloc(n); /* lives as long as the process */
    if (!path)
      return -1;
    snprintf(path, n, "%s_%s.png", prefix, bb_output_kind_get((bb_output_kind)k)->name);
    job->paths[k] = path;
  }
  job->prefix = NULL;
  return 0;
}

int bb_cli_serve(int argc, char **argv) {
  enum { MAX_ROWS = 48 };
  const cli_option *rows[MAX_ROWS];
  int count = 0;
  for (int i = 0; i < cli_bake_parameter_row_count && count < MAX_ROWS - 4; i++)
    rows[count++] = cli_bake_parameter_rows[i];
  rows[count++] = &opt_port;
  rows[count++] = &opt_address;
  rows[count++] = &opt_quiet;
  rows[count++] = &cli_opt_help;
  const cli_command command = {
      "serve",
      "HEIGHT --scale S [OPTIONS]",
      "Bakes HEIGHT, serves a page that shows its maps lit in the browser (the\n"
      "ssbump under a light you drag, normal-mapped, ao, bent normal, basis\n"
      "weights, relief; tiled to show seams) and re-bakes when HEIGHT, or a\n"
      "map the options read, is saved, or when a control on the page changes.\n"
      "Nothing is written until the page's \"write\" asks: then the maps are\n"
      "written as the `bumpbake bake` line the page shows would write them\n"
      "(PREFIX_normal.png, PREFIX_ssbump.png, PREFIX_ao.png by default, PREFIX\n"
      "being HEIGHT without its extension). Listens on 127.0.0.1 unless told;\n"
      "Ctrl-C stops. See docs/commands/serve.md.",
      rows,
      count,
      cli_settings_init,
  };
  serve_args a;
  memset(&a, 0, sizeof a);
  cli_settings_init(&a.settings);
  bb_job_options_init(&a.job);
  a.port = SERVE_DEFAULT_PORT;
  int first = 0;
  int rc = cli_parse_options(&command, argc, argv, serve_option, &a, &first);
  if (rc < 0)
    return BB_EXIT_OK; /* --help */
  if (!rc)
    rc = cli_expect_positionals(&command, argc, argv, first, 1, "HEIGHT");
  if (!rc && !a.settings.scale_given)
    rc = cli_usage_error("serve",
                         "--scale is required (texels of displacement per unit of height)");
  if (rc)
    return rc;
  const char *height = argv[first];
  if (name_outputs(&a.job, height) != 0) {
    cli_error_line("out of memory");
    return BB_EXIT_FAILURE;
  }

  static serve_state s; /* the threads use it until the process ends */
  pthread_mutex_init(&s.lock, NULL);
  pthread_cond_init(&s.work, NULL);
  pthread_cond_init(&s.changed, NULL);
  s.height_path = height;
  s.settings = a.settings;
  s.job = a.job;
  s.brightness_file = a.job.brightness_file;
  s.use_brightness = s.brightness_file != NULL;
  s.quiet = a.quiet;
  s.watched[s.watched_count++] = height;
  const char *also[] = {a.job.brightness_file, a.job.bounce_albedo_file,
                        a.settings.basis_file};
  for (size_t i = 0; i < sizeof also / sizeof also[0]; i++)
    if (also[i])
      s.watched[s.watched_count++] = also[i];

  /* A height that cannot be read at all is a mistake on the command line,
   * not a save to wait for (a broken save later keeps the page going). */
  bb_error err = {{0}};
  bb_status st = bb_image_read_info(height, NULL, NULL, NULL, NULL, &err);
  if (st != BB_OK)
    return cli_status_exit(height, st, &err);
  /* The options and files checked once by the library before serving. */
  bb_job_options o;
  serve_job_options(&s, &o);
  bb_job *job = NULL;
  st = bb_job_plan(&height, 1, &o, &job, &err);
  bb_job_free(job);
  if (st != BB_OK)
    return cli_library_error("serve", st, &err);

  char message[512];
  if (serve_watch_start(&s, message, sizeof message) != 0) {
    cli_error_line(message);
    return BB_EXIT_FAILURE;
  }
  pthread_t baker;
  if (pthread_create(&baker, NULL, serve_bake_thread, &s) != 0) {
    cli_error_line("serve: cannot start the bake thread");
    return BB_EXIT_FAILURE;
  }
  pthread_mutex_lock(&s.lock);
  serve_request_bake(&s);
  pthread_mutex_unlock(&s.lock);
  serve_http_options http = {a.address, a.port, a.address != NULL};
  char url[256];
  if (serve_http_start(&s, &http, url, sizeof url) != 0) {
    char line[400];
    snprintf(line, sizeof line, "serve: %s", url);
    cli_error_line(line);
    return BB_EXIT_FAILURE;
  }
  printf("serve: %s (Ctrl-C stops)\n", url);
  fflush(stdout);
  for (;;)
    pause(); /* a signal ends the process (cli_install_signal_handlers) */
}
