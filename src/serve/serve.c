/* serve.c: `bumpbake serve`, a bake seen live: the height baked with
 * bake's options, watched, re-baked on every save, and shown lit in the
 * browser (src/serve/, a client beside the CLI, whose printing it
 * shares). This file keeps the command line's words. */
#include "serve.h"
#include "../cli/cli.h"
#include "../cli/common.h"
#include "bumpbake_cluster.h"

#include <arpa/inet.h>
#include <limits.h>
#include <netinet/in.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

/* The write action's files: as the command line names them
 * (bb_command_map_file: -o PREFIX's, HEIGHT's without its extension when
 * no output is named, or each map's own), spelled out one by one
 * (--normal P_normal.png ...) so that the command line the page shows is
 * the whole job. 0, or -1 when out of memory. */
static int name_outputs(serve_state *s, const bb_command *line) {
  for (int k = 0; k < BB_MAP_BAKED_COUNT; k++)
    if (bb_command_map_file(line, (bb_map_kind)k, &s->write_files[k], NULL) != BB_OK)
      return -1;
  return 0;
}

/* The file of basis option name, or NULL when it names none (a basis of
 * the library's, by its name: bb_basis_resolve's rule). */
static const char *basis_file(const cli_run *r, const char *name) {
  char text[PATH_MAX];
  int from_file = 0;
  bb_basis basis;
  if (!cli_text(r, name, text, sizeof text) ||
      bb_basis_resolve(text, &basis, &from_file, NULL) != BB_OK || !from_file)
    return NULL;
  return strdup(text);
}

/* The file option name of command names, kept for the process's life
 * (serve's state holds it), or NULL when not given. */
static const char *kept_path(const cli_run *r, const char *name) {
  char path[PATH_MAX];
  return cli_text(r, name, path, sizeof path) ? strdup(path) : NULL;
}

int cli_run_serve(const cli_run *r) {
  const char *height = bb_command_input(r->command, 0);
  static serve_state s; /* the threads use it until the process ends */
  if (name_outputs(&s, r->command) != 0) {
    cli_error_line("out of memory");
    return BB_EXIT_FAILURE;
  }
  pthread_mutex_init(&s.lock, NULL);
  pthread_cond_init(&s.work, NULL);
  pthread_cond_init(&s.changed, NULL);
  s.height_path = height;
  s.line = r->command; /* lives as long as the process */
  s.albedo_file = kept_path(r, "albedo"); /* render's --albedo and --light-color light
                                             the picture */
  serve_light_color(r->command, s.light_color);
  s.quiet = r->quiet;
  /* the page's controls change a copy of the command line's command */
  size_t handover_size = 0;
  char *handover = bb_command_handover(r->command, &handover_size);
  bb_error copy_err = {{0}};
  bb_status copied = handover ? bb_command_from_handover(handover, handover_size, NULL, 0,
                                                         &s.command, &copy_err)
                              : BB_ERR_MEMORY;
  free(handover);
  if (copied != BB_OK)
    return cli_library_error("serve", copied, &copy_err);
  s.watched[s.watched_count++] = height;
  /* the files the bake reads beside the height, by their options */
  const char *also[] = {kept_path(r, "brightness"), kept_path(r, "bounce-albedo"),
                        basis_file(r, "basis"), s.albedo_file};
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
  bb_command *planned = NULL;
  bb_job *job = NULL;
  char *planned_line = NULL;
  st = serve_bake_command(&s, &planned, &planned_line, &err);
  if (st == BB_OK)
    st = bb_command_plan(planned, NULL, &job, &err);
  bb_job_free(job);
  bb_command_free(planned);
  free(planned_line);
  if (st != BB_OK)
    return cli_library_error("serve", st, &err);

  /* the ray set and the buffers stay warm from one bake to the next, and
   * what the last bake made: a save that changes part of the height bakes
   * again only what the change reaches (the same bits) */
  bb_error context_err = {{0}};
  if (bb_bake_context_new(&s.context, &context_err) != BB_OK)
    return cli_library_error("serve", BB_ERR_MEMORY, &context_err);
  bb_bake_context_keep(s.context, 1);

  /* Listening comes before any bake, so a port already taken ends serve
   * before a bake starts; every thread started before a failure is
   * stopped and joined before the command they read is freed. */
  char message[512];
  serve_watch *watch = NULL;
  if (serve_watch_start(&s, &watch, message, sizeof message) != 0) {
    bb_bake_context_free(s.context);
    cli_error_line(message);
    return BB_EXIT_FAILURE;
  }
  /* where it listens: serve's own options, read through the command */
  char port[16], address[128];
  if (bb_command_value(r->command, "port", port, sizeof port, &err) != BB_OK ||
      bb_command_value(r->command, "address", address, sizeof address, &err) != BB_OK) {
    serve_watch_stop(watch);
    bb_bake_context_free(s.context);
    return cli_library_error("serve", BB_ERR_ARGUMENT, &err);
  }
  serve_http_options http = {address, atoi(port), bb_command_given(r->command, "address")};
  char url[256];
  if (serve_http_start(&s, &http, url, sizeof url) != 0) {
    serve_watch_stop(watch);
    bb_bake_context_free(s.context);
    char line[400];
    snprintf(line, sizeof line, "serve: %s", url);
    cli_error_line(line);
    return BB_EXIT_FAILURE;
  }
  pthread_t baker;
  if (pthread_create(&baker, NULL, serve_bake_thread, &s) != 0) {
    serve_http_stop(&s);
    serve_watch_stop(watch);
    bb_bake_context_free(s.context);
    cli_error_line("serve: cannot start the bake thread");
    return BB_EXIT_FAILURE;
  }
  pthread_mutex_lock(&s.lock);
  serve_request_bake(&s);
  pthread_mutex_unlock(&s.lock);
  printf("serve: %s (Ctrl-C stops)\n", url);
  fflush(stdout);
  for (;;)
    pause(); /* a signal ends the process (cli_install_signal_handlers) */
}
