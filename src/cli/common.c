/* cli_common.c: what the bumpbake subcommands share besides options
 * (cli_options.c), outputs (cli_outputs.c), progress (cli_progress.c) and
 * JSON (cli_json.c): error messages, reading inputs, signals. */
#include "common.h"

#include <fcntl.h>
#include <signal.h>
#include <stdarg.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

/* ----------------------------------------------------------------- errors */

int cli_usage_error(const char *command, const char *fmt, ...) {
  va_list ap;
  va_start(ap, fmt);
  fprintf(stderr, "bumpbake %s: ", command);
  vfprintf(stderr, fmt, ap);
  fputc('\n', stderr);
  va_end(ap);
  return BB_EXIT_USAGE;
}

void cli_file_error(const char *path, const char *reason) {
  /* Errors are one line, whatever a lower layer put in its message. */
  char line[2 * sizeof(bb_error)];
  snprintf(line, sizeof line, "%s", reason && *reason ? reason : "unknown error");
  for (char *c = line; *c; c++)
    if (*c == '\n' || *c == '\r')
      *c = ' ';
  size_t n = strlen(path);
  if (strncmp(line, path, n) == 0 && line[n] == ':')
    fprintf(stderr, "bumpbake: %s\n", line);
  else
    fprintf(stderr, "bumpbake: %s: %s\n", path, line);
}

int cli_status_exit(const char *path, bb_status status, const bb_error *err) {
  if (status == BB_OK)
    return 0;
  cli_file_error(path, err->message[0] ? err->message : bb_status_name(status));
  return BB_EXIT_FAILURE;
}

/* libpng, inside OpenImageIO, prints its own "libpng error: ..." line on
 * stderr for a corrupt PNG before OpenImageIO returns the error we report.
 * The CLI mutes stderr while decoding so every error stays one line; the
 * library leaves the process's file descriptors alone. */
int cli_mute_stderr(void) {
  fflush(stderr);
  int saved = dup(STDERR_FILENO), null_fd = open("/dev/null", O_WRONLY);
  if (saved >= 0 && null_fd >= 0) dup2(null_fd, STDERR_FILENO);
  if (null_fd >= 0) close(null_fd);
  return saved;
}

void cli_unmute_stderr(int saved) {
  if (saved < 0) return;
  dup2(saved, STDERR_FILENO);
  close(saved);
}

bb_status cli_read_image(const char *path, bb_image *img, bb_image_info *info, bb_error *err) {
  int saved = cli_mute_stderr();
  bb_status st = bb_image_read(path, img, info, err);
  cli_unmute_stderr(saved);
  return st;
}

int cli_load_height(const char *path, const cli_settings *s, bb_image *height) {
  return cli_load_height_source(path, s, height, NULL);
}

int cli_load_height_source(const char *path, const cli_settings *s, bb_image *height,
                           cli_height_source *source) {
  bb_image img = {0};
  bb_image_info info;
  bb_error err = {{0}};
  bb_status st = cli_read_image(path, &img, &info, &err);
  if (st == BB_OK) {
    /* The rule's own choice, so a height found in alpha is said once. */
    bb_channel used = bb_height_channel(&img, info.alpha_channel, s->channel);
    if (source) {
      const int alpha = info.alpha_channel >= 0 || img.channels == 2 || img.channels == 4;
      *source = (cli_height_source){used, img.channels - alpha < 3, info.bits_per_sample,
                                    info.is_float};
    }
    if (s->channel == BB_CHANNEL_AUTO && used == BB_CHANNEL_A)
      fprintf(stderr,
              "bumpbake: %s: note: the colour is constant and alpha is not; using "
              "alpha as the height (Valve's convention; --channel chooses)\n",
              path);
    st = bb_height_from_image(&img, info.alpha_channel, used, height, &err);
    bb_image_info_free(&info);
    bb_image_free(&img);
  }
  return cli_status_exit(path, st, &err);
}

const char *cli_height_channel_name(const cli_height_source *source) {
  /* The mean of one colour channel is that channel. */
  if (source->grey && (source->channel == BB_CHANNEL_MEAN || source->channel == BB_CHANNEL_LUMA))
    return "grey";
  return bb_channel_name(source->channel);
}

bb_depth cli_depth_like_input(const cli_height_source *source, const char *path) {
  /* The closest the format holds, from the input's own depth downwards. */
  static const bb_depth float_order[] = {BB_DEPTH_FLOAT, BB_DEPTH_HALF, BB_DEPTH_16};
  static const bb_depth half_order[] = {BB_DEPTH_HALF, BB_DEPTH_FLOAT, BB_DEPTH_16};
  static const bb_depth int16_order[] = {BB_DEPTH_16, BB_DEPTH_FLOAT};
  const bb_depth *order = NULL;
  size_t n = 0;
  if (source->is_float && source->bits_per_sample <= 16)
    order = half_order, n = 3;
  else if (source->is_float)
    order = float_order, n = 3;
  else if (source->bits_per_sample > 8)
    order = int16_order, n = 2;
  for (size_t i = 0; i < n; i++)
    if (bb_path_supports_depth(path, order[i]))
      return order[i];
  return BB_DEPTH_DEFAULT;
}

int cli_check_hl2_map(const char *path, const bb_image *img, const bb_image_info *info) {
  char basis[64], reason[256];
  bb_provenance_value(info ? info->description : NULL, "basis", basis, sizeof basis);
  if (basis[0] && strcmp(basis, "hl2") && strcmp(basis, "hl2+z") && strcmp(basis, "dirs:3"))
    snprintf(reason, sizeof reason,
             "baked with --basis %s; this reads Half-Life 2's basis (bake with --basis hl2)",
             basis);
  else if (img->channels > 4)
    snprintf(reason, sizeof reason,
             "%d channels, one per direction of a basis other than Half-Life 2's; this "
             "reads Half-Life 2's 3 (bake with --basis hl2)",
             img->channels);
  else
    return 0;
  cli_file_error(path, reason);
  return BB_EXIT_FAILURE;
}

int cli_run_bake(const char *path, const bb_image *height, const bb_bake_options *o,
                 bb_bake_result *result) {
  bb_error err = {{0}};
  bb_status st = bb_bake(height, o, result, &err);
  return cli_status_exit(path, st, &err);
}

double cli_now_seconds(void) {
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* ---------------------------------------------------------------- signals */

/* Removes the temporaries of the writes in progress, then dies of the same
 * signal: SA_RESETHAND has restored the default action, and the signal,
 * blocked while this runs, is delivered when it returns, so the exit status
 * is what a shell expects of Ctrl-C or kill. Only async-signal-safe calls. */
static void remove_temporaries_and_die(int sig) {
  bb_tempfiles_remove();
  raise(sig);
}

void cli_install_signal_handlers(void) {
  /* Over RLIMIT_FSIZE a write then fails with EFBIG, reported and cleaned
   * up like a full disk, instead of SIGXFSZ killing the process with its
   * temporary left behind. */
  struct sigaction ignore;
  memset(&ignore, 0, sizeof ignore);
  ignore.sa_handler = SIG_IGN;
  sigemptyset(&ignore.sa_mask);
  sigaction(SIGXFSZ, &ignore, NULL);

  static const int fatal[] = {SIGINT, SIGTERM, SIGHUP};
  for (size_t i = 0; i < sizeof fatal / sizeof fatal[0]; i++) {
    struct sigaction old, sa;
    /* A signal ignored by whoever started us (nohup, a background job)
     * stays ignored. */
    if (sigaction(fatal[i], NULL, &old) == 0 && old.sa_handler == SIG_IGN)
      continue;
    memset(&sa, 0, sizeof sa);
    sa.sa_handler = remove_temporaries_and_die;
    sigemptyset(&sa.sa_mask);
    sa.sa_flags = (int)SA_RESETHAND;
    sigaction(fatal[i], &sa, NULL);
  }
}
