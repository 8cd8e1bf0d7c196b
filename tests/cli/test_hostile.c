/* test_hostile.c: files and names meant to hurt, run through the program:
 * outputs over the files a command reads, names from a template that leave
 * the output directory, a signal in the middle of a commit, depfiles that
 * cannot be written or cannot say a name, program images outside their
 * base, and text that would drive a terminal or break JSON. Each case
 * ends in one line and a non-zero exit, with nothing changed that should
 * not be. */
#define _XOPEN_SOURCE 700 /* mkdtemp, nftw, realpath */
#define _DEFAULT_SOURCE    /* wait4 (cli_harness.h) */

#include "bumpbake.h"
#include "cli_harness.h"
#include "printed_text.h"
#include "files/safe_file.h"
#include "image/image_write.h"

#include <fcntl.h>
#include <math.h>
#include <sys/sysmacros.h>

TestSuite(hostile, .init = harness_setup, .fini = harness_teardown, .timeout = 300);

#define FAST "--scale", "6", "--slices", "4", "--filter-radius", "2"

static void height_file(const char *path) {
  bb_image h;
  cr_assert_eq(bb_image_alloc(&h, 16, 16, 1, NULL), BB_OK);
  for (int i = 0; i < 256; i++)
    h.pixels[i] = (float)(0.5 + 0.3 * sin(0.7 * (i % 16)) * cos(0.5 * (i / 16)));
  harness_write(path, &h, BB_DEPTH_16, BB_RANGE_UNIT);
  bb_image_free(&h);
}

static unsigned char *slurp_file(const char *path, size_t *size) {
  FILE *f = fopen(path, "rb");
  cr_assert_not_null(f, "%s", path);
  char *text = harness_slurp(f);
  fseek(f, 0, SEEK_END);
  *size = (size_t)ftell(f);
  fclose(f);
  return (unsigned char *)text;
}

/* 1 when the file's bytes are the same as before. */
static int unchanged(const char *path, const unsigned char *before, size_t size) {
  size_t now_size;
  unsigned char *now = slurp_file(path, &now_size);
  int same = now_size == size && memcmp(now, before, size) == 0;
  free(now);
  return same;
}

/* ------------------------------------------------- FIFOs and devices */

/* Every command that reads a file refuses a FIFO (which blocked in open()
 * for ever) and a link to /dev/zero (read without end) at once: one line
 * naming it, exit 1 (compare: idiff's 4), nothing written. */
Test(hostile, fifos_and_devices_are_refused_by_every_command) {
  height_file(tmp("h.png"));
  cli_result baked = RUN("bake", tmp("h.png"), FAST, "--ssbump", tmp("s.png"));
  cr_assert_eq(baked.code, 0, "%s", baked.err);
  cli_result_free(&baked);
  cr_assert_eq(mkfifo(tmp("f.png"), 0644), 0);
  cr_assert_eq(mkfifo(tmp("f.txt"), 0644), 0);
  cr_assert_eq(symlink("/dev/zero", tmp("z.png")), 0);
  cr_assert_eq(symlink("/dev/zero", tmp("z.txt")), 0);
  for (int device = 0; device < 2; device++) {
    const char *img = device ? "z.png" : "f.png", *txt = device ? "z.txt" : "f.txt";
    char expr[64];
    snprintf(expr, sizeof expr, "invertColor(%s)", img);
    const struct {
      const char *args[16];
      int code;
      const char *name;
    } runs[] = {
        {{"info", img}, 1, img},
        {{"bake", img, FAST, "--normal", "o.png"}, 1, img},
        {{"compare", "h.png", img}, 4, img},
        {{"program", expr, "-o", "o.png"}, 1, img},
        {{"render", img, "--scale", "6", "-o", "o.png"}, 1, img},
        {{"render", "--ssbump", "s.png", "--albedo", img, "-o", "o.png"}, 1, img},
        {{"bake", "h.png", FAST, "--basis", txt, "--ssbump", "o.png"}, 1, txt},
    };
    for (size_t i = 0; i < sizeof runs / sizeof runs[0]; i++) {
      cli_result r = harness_run_in(harness_dir, runs[i].args);
      cr_expect_eq(r.code, runs[i].code, "%s %s: exit %d: %s", runs[i].args[0], runs[i].name,
                   r.code, r.err);
      cr_expect_eq(harness_lines(r.err), 1, "%s %s: %s", runs[i].args[0], runs[i].name, r.err);
      cr_expect(strstr(r.err, runs[i].name), "%s: %s", runs[i].args[0], r.err);
      /* (a FIFO that blocked would hit the suite's timeout; /dev/zero read
       * without end spins: CPU time, which load does not stretch) */
      cr_expect_lt(r.cpu_seconds, 5.0, "%s %s took %.1f s of CPU", runs[i].args[0],
                   runs[i].name, r.cpu_seconds);
      cli_result_free(&r);
      cr_expect(!file_exists(tmp("o.png")), "%s %s wrote its output", runs[i].args[0],
                runs[i].name);
    }
  }
}

/* A 2 GiB file of zeros (sparse) named .png: every command refuses it in
 * one line naming the format its extension promised, in well under a
 * second of CPU (OpenImageIO's fallback through every reader, and the hash
 * of the file's bytes before its header was looked at, took minutes). The
 * other extensions are the library's test (untrusted). */
Test(hostile, a_large_file_no_reader_knows_is_refused_by_every_command) {
  height_file(tmp("h.png"));
  cli_result baked = RUN("bake", tmp("h.png"), FAST, "--ssbump", tmp("s.png"));
  cr_assert_eq(baked.code, 0, "%s", baked.err);
  cli_result_free(&baked);
  cr_assert_eq(mkdir(tmp("batch"), 0755), 0);
  int fd = open(tmp("batch/z.png"), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  cr_assert(fd >= 0 && ftruncate(fd, (off_t)2 << 30) == 0);
  close(fd);
  cr_assert_eq(link(tmp("batch/z.png"), tmp("z.png")), 0);
  const struct {
    const char *args[16];
    int code;
  } runs[] = {
      {{"info", "z.png"}, 1},
      {{"bake", "z.png", FAST, "--normal", "o.png"}, 1},
      {{"bake", "batch", "--out-dir", "out", FAST}, 1},
      {{"normal", "z.png", "--scale", "4", "-o", "o.png"}, 1},
      {{"height2ssbump", "z.png", "4"}, 1},
      {{"compare", "h.png", "z.png"}, 4},
      {{"render", "z.png", "--scale", "6", "-o", "o.png"}, 1},
      {{"render", "--ssbump", "s.png", "--albedo", "z.png", "-o", "o.png"}, 1},
      {{"sheet", "z.png", "--scale", "6", "-o", "o.png"}, 1},
      {{"program", "invertColor(z.png)", "-o", "o.png"}, 1},
      {{"normal2ssbump", "z.png", "-o", "o.png"}, 1},
      {{"combine", "z.png", "h.png", "--mix", "0.5", "-o", "o.png"}, 1},
  };
  for (size_t i = 0; i < sizeof runs / sizeof runs[0]; i++) {
    cli_result r = harness_run_in(harness_dir, runs[i].args);
    cr_expect_eq(r.code, runs[i].code, "%s: exit %d: %s", runs[i].args[0], r.code, r.err);
    cr_expect(strstr(r.err, "z.png: not a readable image: its extension says PNG"),
              "%s: %s", runs[i].args[0], r.err);
    cr_expect_lt(r.cpu_seconds, 1.5, "%s took %.1f s of CPU", runs[i].args[0],
                 r.cpu_seconds);
    cli_result_free(&r);
    cr_expect(!file_exists(tmp("o.png")), "%s wrote its output", runs[i].args[0]);
  }
}

/* What stands at a name, as lstat sees it: 'f' FIFO, 'l' link, 'r' regular. */
static char kind_at(const char *path) {
  struct stat st;
  if (lstat(path, &st) != 0) return '-';
  return S_ISFIFO(st.st_mode) ? 'f' : S_ISLNK(st.st_mode) ? 'l' : S_ISREG(st.st_mode) ? 'r' : '?';
}

/* An output that exists and is not a regular file (a FIFO, a device, a
 * link to one, /dev/stdout) was renamed over: as root /dev/full became a
 * 13-byte file. Every command refuses it now, in one line, and leaves it
 * as it was; a batch whose output name is a FIFO too, and --vmt. */
Test(hostile, outputs_that_are_not_regular_files_are_never_replaced) {
  height_file(tmp("h.png"));
  cr_assert_eq(mkfifo(tmp("fifo.png"), 0644), 0);
  cr_assert_eq(symlink("/dev/null", tmp("null.png")), 0);
  cr_assert_eq(symlink("/dev/null", tmp("null.vmt")), 0);
  cr_assert_eq(mkdir(tmp("materials"), 0755), 0);
  cr_assert_eq(mkdir(tmp("out"), 0755), 0);
  cr_assert_eq(mkfifo(tmp("out/h_normal.png"), 0644), 0);
  const struct {
    const char *args[16];
    const char *name, *part;
  } runs[] = {
      {{"bake", "h.png", FAST, "--normal", "fifo.png"}, "fifo.png", "is a FIFO"},
      {{"bake", "h.png", FAST, "--ssbump", "null.png"}, "null.png", "symbolic link (to a character device)"},
      {{"bake", "h.png", FAST, "--ssbump", "materials/s.vtf", "--vmt", "null.vmt"}, "null.vmt", "symbolic link"},
      {{"bake", "h.png", FAST, "--out-dir", "out", "--maps", "normal"}, "out/h_normal.png", "is a FIFO"},
      {{"normal", "h.png", "--scale", "4", "-o", "fifo.png"}, "fifo.png", "is a FIFO"},
      {{"render", "h.png", "--scale", "6", "--rays", "16", "-o", "null.png"}, "null.png", "symbolic link"},
  };
  for (size_t i = 0; i < sizeof runs / sizeof runs[0]; i++) {
    char what[64];
    snprintf(what, sizeof what, "%s %s", runs[i].args[0], runs[i].name);
    cli_result r = harness_run_in(harness_dir, runs[i].args);
    harness_expect_error(&r, 1, runs[i].part, what);
    cr_expect(strstr(r.err, runs[i].name), "%s: %s", what, r.err);
    cli_result_free(&r);
  }
  cr_expect_eq(kind_at(tmp("fifo.png")), 'f');
  cr_expect_eq(kind_at(tmp("out/h_normal.png")), 'f');
  cr_expect_eq(kind_at(tmp("null.png")), 'l');
  cr_expect_eq(kind_at(tmp("null.vmt")), 'l');
  cr_expect(!file_exists(tmp("materials/s.vtf")), "the texture of a refused material was written");
  /* The library's own writers refuse them too. */
  bb_error err;
  cr_expect_eq(bb__file_write(tmp("fifo.png"), "x", 1, &err), BB_ERR_IO);
  cr_expect(strstr(err.message, "is a FIFO"), "%s", err.message);
  bb_image img;
  cr_assert_eq(bb_image_alloc(&img, 4, 4, 1, NULL), BB_OK);
  bb_write_options wo = {BB_DEPTH_8, BB_RANGE_UNIT, NULL, NULL};
  cr_expect_eq(bb__image_write(tmp("null.png"), &img, &wo, &err), BB_ERR_IO);
  bb_image_free(&img);
  cr_expect_eq(kind_at(tmp("fifo.png")), 'f');
  cr_expect_eq(kind_at(tmp("null.png")), 'l');
  cr_expect_eq(files_starting_with(".bb-tmp"), 0);
  /* As root, a device node in the test's directory (what /dev/full was). */
  if (geteuid() == 0 && mknod(tmp("full.png"), S_IFCHR | 0666, makedev(1, 7)) == 0) {
    cli_result r = RUN_IN(harness_dir, "bake", "h.png", FAST, "--normal", "full.png");
    harness_expect_error(&r, 1, "is a character device", "a device node");
    cli_result_free(&r);
    struct stat st;
    cr_expect(lstat(tmp("full.png"), &st) == 0 && S_ISCHR(st.st_mode), "the device was replaced");
  }
}

/* A depfile is text a build tool reads: through a FIFO or a character
 * device (/dev/stdout on a pipe, /dev/null) it is written through, not
 * replaced; a full device is an error after the maps; a FIFO nobody reads
 * is an error, not a wait. */
Test(hostile, a_depfile_is_written_through_a_stream) {
  height_file(tmp("h.png"));
  cr_assert_eq(symlink("/dev/null", tmp("null.d")), 0);
  cr_assert_eq(symlink("/dev/full", tmp("full.d")), 0);
  cr_assert_eq(mkfifo(tmp("fifo.d"), 0644), 0);
  cli_result r = RUN_IN(harness_dir, "bake", "h.png", FAST, "--normal", "n.png", "--depfile", "null.d");
  cr_expect_eq(r.code, 0, "%s", r.err);
  cli_result_free(&r);
  cr_expect_eq(kind_at(tmp("null.d")), 'l');
  cr_expect(file_exists(tmp("n.png")));
  r = RUN_IN(harness_dir, "bake", "h.png", FAST, "--normal", "n2.png", "--depfile", "full.d");
  harness_expect_error(&r, 1, "No space left on device; the maps were written", "/dev/full");
  cli_result_free(&r);
  cr_expect_eq(kind_at(tmp("full.d")), 'l');
  r = RUN_IN(harness_dir, "bake", "h.png", FAST, "--normal", "n3.png", "--depfile", "fifo.d");
  harness_expect_error(&r, 1, "no process reads the FIFO", "a FIFO without a reader");
  cli_result_free(&r);
  /* With a reader (open before the bake, read after it: the rule fits in
   * the pipe's buffer), the rule arrives through the FIFO. */
  const int reader = open(tmp("fifo.d"), O_RDONLY | O_NONBLOCK);
  cr_assert_geq(reader, 0);
  r = RUN_IN(harness_dir, "bake", "h.png", FAST, "--normal", "n4.png", "--depfile", "fifo.d");
  cr_expect_eq(r.code, 0, "%s", r.err);
  cli_result_free(&r);
  char line[256] = "";
  const ssize_t got = read(reader, line, sizeof line - 1);
  close(reader);
  cr_expect_str_eq(line, "n4.png: h.png\n", "read %zd bytes", got);
  cr_expect_eq(kind_at(tmp("fifo.d")), 'f');
}

/* --------------------------------------------- outputs over what is read */

/* render checks its picture against every file it reads: the albedo, the
 * height, and each frame of an orbit. */
Test(hostile, render_never_writes_over_what_it_reads) {
  height_file(tmp("h.png"));
  const char *bake[] = {"bake", tmp("h.png"), FAST, "--ssbump", tmp("s.png"), NULL};
  cli_result r = harness_run(bake);
  cr_assert_eq(r.code, 0, "%s", r.err);
  cli_result_free(&r);
  height_file(tmp("a.png")); /* an albedo */
  size_t size;
  unsigned char *albedo = slurp_file(tmp("a.png"), &size);
  const char *over_albedo[] = {"render", "--ssbump", tmp("s.png"), "--albedo", tmp("a.png"),
                               "-o", tmp("a.png"), NULL};
  harness_expect_refusal(NULL, over_albedo, 1, "would overwrite the input", 1);
  cr_expect(unchanged(tmp("a.png"), albedo, size), "the albedo was replaced");
  free(albedo);
  const char *over_height[] = {"render", tmp("h.png"), "--scale", "6", "--rays", "16",
                               "--albedo", tmp("a.png"), "-o",
                               tmp("h.png"), NULL};
  harness_expect_refusal(NULL, over_height, 1, "would overwrite the input", 2);
  /* An orbit's frame r_000.png is the ssbump it lights. */
  r = harness_run((const char *[]){"bake", tmp("h.png"), FAST, "--ssbump", tmp("r_000.png"),
                                   NULL});
  cli_result_free(&r);
  unsigned char *frame = slurp_file(tmp("r_000.png"), &size);
  const char *over_frame[] = {"render", "--ssbump", tmp("r_000.png"), "--orbit", "2", "-o",
                              tmp("r.png"), NULL};
  harness_expect_refusal(NULL, over_frame, 1, "would overwrite the input", 3);
  cr_expect(unchanged(tmp("r_000.png"), frame, size), "a frame replaced its input");
  cr_expect(!file_exists(tmp("r_001.png")), "a frame was written");
  free(frame);
}

/* ------------------------------------------------ names from a template */

/* An input named "...png" has the stem "..": "{stem}/{kind}.png" would
 * write ./normal.png beside the out-dir. */
Test(hostile, template_names_stay_inside_the_out_dir) {
  cr_assert_eq(mkdir(tmp("in"), 0755), 0);
  height_file(tmp("in/...png"));
  const char *args[] = {"bake", tmp("in/...png"), FAST, "--out-dir", tmp("out"), "--name",
                        "{stem}/{kind}.png", NULL};
  harness_expect_refusal(NULL, args, 2, "would leave the output directory", 4);
  cr_expect(!file_exists(tmp("normal.png")) && !file_exists(tmp("out/normal.png")));
  const char *literal[] = {"bake", tmp("in/...png"), FAST, "--out-dir", tmp("out"), "--name",
                           "../{stem}_{kind}.png", NULL};
  harness_expect_refusal(NULL, literal, 2, "would leave the output directory", 5);
  const char *absolute[] = {"bake", tmp("in/...png"), FAST, "--out-dir", tmp("out"), "--name",
                            "/tmp/{stem}_{kind}.png", NULL};
  harness_expect_refusal(NULL, absolute, 2, "relative to the output directory", 6);
}

/* ---------------------------------------------------- signals in commits */

/* 1 when strace can inject a signal into a child here (ptrace allowed). */
static int strace_works(void) {
  return system("strace -f -o /dev/null -e trace=none true >/dev/null 2>&1") == 0;
}

/* A SIGINT delivered at the second rename of a set: the old binary left two
 * maps new and two old; the set must be all old or all new. The bake starts
 * with SIGINT at its default (env --default-signal): a suite started in the
 * background by a shell without job control inherits it ignored, and the
 * CLI keeps an ignored SIGINT ignored, as under nohup. */
Test(hostile, a_signal_during_a_commit_leaves_the_set_whole) {
  if (!strace_works())
    cr_skip_test("strace cannot trace here");
  height_file(tmp("h.png"));
  const char *bin = harness_binary();
  char command[16384];
  snprintf(command, sizeof command,
           "cd '%s' && '%s' bake h.png --scale 4 --slices 4 -o r --bent r_bent.exr -q && "
           "cp r_normal.png n0 && cp r_ao.png a0 && cp r_bent.exr b0 && "
           "env --default-signal=INT strace -f -o /dev/null -e trace=rename "
           "-e inject=rename:signal=SIGINT:when=2 "
           "'%s' bake h.png --scale 9 --slices 4 -o r --bent r_bent.exr -q; "
           "cmp -s r_normal.png n0; n=$?; cmp -s r_ao.png a0; a=$?; cmp -s r_bent.exr b0; "
           "b=$?; test $n = $a && test $a = $b",
           tmp(""), bin, bin);
  cr_expect_eq(system(command), 0, "after a SIGINT in the renames, some maps are new and "
                                   "some old");
  cr_expect_eq(files_starting_with(".bb-tmp"), 0, "a temporary was left");
}

/* An orbit's frames are one set: a SIGINT at the second of four renames
 * left frames 0..1 new and 2..3 old (12 of 22 before). */
Test(hostile, a_signal_during_an_orbit_commit_leaves_the_frames_whole) {
  if (!strace_works())
    cr_skip_test("strace cannot trace here");
  height_file(tmp("h.png"));
  const char *bin = harness_binary();
  char command[16384];
  snprintf(command, sizeof command,
           "cd '%s' && '%s' render h.png --scale 6 --rays 16 --orbit 4 --light 0,30 -o x.png -q "
           "&& for i in 0 1 2 3; do cp x_00$i.png old$i; done && "
           "env --default-signal=INT strace -f -o /dev/null -e trace=rename "
           "-e inject=rename:signal=SIGINT:when=2 "
           "'%s' render h.png --scale 6 --rays 16 --orbit 4 --light 0,60 -o x.png -q; "
           "test $? = 130 || exit 2; new=0; for i in 0 1 2 3; do cmp -s x_00$i.png old$i || "
           "new=$((new + 1)); done; test $new = 0 || test $new = 4",
           tmp(""), bin, bin);
  int status = system(command);
  cr_expect_neq(WEXITSTATUS(status), 2, "the interrupted orbit did not exit 130");
  cr_expect_eq(status, 0, "after a SIGINT in the renames, some frames are new and some old");
  cr_expect_eq(files_starting_with(".bb-tmp"), 0, "a temporary was left");
}

/* ---------------------------------------------------------------- depfiles */

/* A depfile that cannot be written is found before the bake: the maps
 * stay as they were. */
Test(hostile, an_unwritable_depfile_is_refused_before_the_bake) {
  if (geteuid() == 0)
    cr_skip_test("root writes into read-only directories");
  height_file(tmp("h.png"));
  cr_assert_eq(mkdir(tmp("ro"), 0555), 0);
  const char *args[] = {"bake", tmp("h.png"), FAST, "--ao", tmp("ao.png"), "--depfile",
                        tmp("ro/h.d"), NULL};
  harness_expect_refusal(NULL, args, 1, "ro", 7);
  cr_expect(!file_exists(tmp("ao.png")), "the map was written");
}

/* The command that runs its arguments in a mount namespace of its own
 * (root's, or a user namespace's), or NULL when there is none here. */
static const char *mount_namespace(void) {
  if (geteuid() == 0 && system("unshare -m true >/dev/null 2>&1") == 0)
    return "unshare -m";
  if (system("unshare -Urm true >/dev/null 2>&1") == 0)
    return "unshare -Urm";
  return NULL;
}

/* A depfile whose file system is full, or read-only even for root: it
 * failed after the maps were replaced. Now it is written with them, so
 * the maps there before stay as they were, and the message names it. */
Test(hostile, a_depfile_on_a_full_or_read_only_file_system_leaves_the_maps) {
  const char *ns = mount_namespace();
  if (!ns)
    cr_skip_test("no mount namespace to make a full or read-only file system in");
  height_file(tmp("h.png"));
  cr_assert_eq(mkdir(tmp("full"), 0755), 0);
  cr_assert_eq(mkdir(tmp("ro"), 0755), 0);
  const char *bin = harness_binary();
  char command[16384];
  snprintf(command, sizeof command,
           "cd '%s' && '%s' bake h.png --scale 4 --slices 4 --ao ao.png --normal n.png -q && "
           "cp ao.png ao0 && cp n.png n0",
           tmp(""), bin);
  cr_assert_eq(system(command), 0);
  static const struct {
    const char *setup, *depfile;
  } places[] = {
      {"mount -t tmpfs -o size=64k none full && dd if=/dev/zero of=full/fill bs=4k "
       ">/dev/null 2>&1; ",
       "full/h.d"},
      {"mount --bind ro ro && mount -o remount,bind,ro ro && ", "ro/h.d"},
  };
  for (size_t i = 0; i < 2; i++) {
    snprintf(command, sizeof command,
             "cd '%s' && %s sh -c '%s exec \"$0\" \"$@\"' '%s' bake h.png --scale 9 --slices 4 "
             "--ao ao.png --normal n.png --depfile %s 2>err.txt; echo $? >code.txt",
             tmp(""), ns, places[i].setup, bin, places[i].depfile);
    cr_assert_eq(system(command), 0);
    size_t size;
    char *code = (char *)slurp_file(tmp("code.txt"), &size);
    char *err = (char *)slurp_file(tmp("err.txt"), &size);
    cr_expect_eq(atoi(code), 1, "%s: exit %s: %s", places[i].depfile, code, err);
    cr_expect_eq(harness_lines(err), 1, "%s: %s", places[i].depfile, err);
    cr_expect(strstr(err, places[i].depfile), "%s", err);
    snprintf(command, sizeof command, "cd '%s' && cmp -s ao.png ao0 && cmp -s n.png n0",
             tmp(""));
    cr_expect_eq(system(command), 0, "%s: the maps were replaced", places[i].depfile);
    free(code);
    free(err);
  }
  cr_expect_eq(files_starting_with(".bb-tmp"), 0, "a temporary was left");
}

/* A single bake's depfile goes in with its maps: a depfile over a
 * directory is refused before anything is baked. */
Test(hostile, a_depfile_on_a_directory_is_refused_before_the_bake) {
  height_file(tmp("h.png"));
  cr_assert_eq(mkdir(tmp("d"), 0755), 0);
  const char *args[] = {"bake", tmp("h.png"), FAST, "--ao", tmp("ao.png"), "--depfile",
                        tmp("d"), NULL};
  harness_expect_refusal(NULL, args, 1, "is a directory", 8);
  cr_expect(!file_exists(tmp("ao.png")));
}

/* Names make and ninja would misread are refused before the bake; a
 * backslash before a space is written as GCC writes it (\\\ ). */
Test(hostile, depfile_names_are_escaped_or_refused) {
  height_file(tmp("t\tx.png"));
  const char *tab[] = {"bake", tmp("t\tx.png"), FAST, "--normal", tmp("o.png"), "--depfile",
                       tmp("o.d"), NULL};
  harness_expect_refusal(NULL, tab, 1, "a tab", 9);
  static const char *const bad[] = {"c:d.png", "e=f.png", "g;h.png", "i%j.png",
                                    "k?l.png", "m*n.png", "p[q].png"};
  for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
    height_file(tmp(bad[i]));
    const char *args[] = {"bake", tmp(bad[i]), FAST, "--normal", tmp("o.png"), "--depfile",
                          tmp("o.d"), NULL};
    harness_expect_refusal(NULL, args, 1, "which a depfile cannot say", 10);
  }
  height_file(tmp("a\\ b#.png"));
  const char *ok[] = {"bake", tmp("a\\ b#.png"), FAST, "--normal", tmp("o.png"), "--depfile",
                      tmp("o.d"), NULL};
  cli_result r = harness_run(ok);
  cr_assert_eq(r.code, 0, "%s", r.err);
  cli_result_free(&r);
  size_t size;
  char *text = (char *)slurp_file(tmp("o.d"), &size);
  cr_expect(strstr(text, "a\\\\\\ b\\#.png"), "depfile: %s", text);
  free(text);
}

/* Each name is either read back as itself by both make and ninja (deps =
 * gcc) from the depfile, or refused before the bake. "k*l.png" was written
 * "k\*l.png", which make reads right and ninja 1.11 reads with its
 * backslash, a file that never exists: ninja baked it on every run. */
Test(hostile, depfile_names_read_back_in_make_and_ninja_or_are_refused) {
  if (system("ninja --version >/dev/null 2>&1 && make --version >/dev/null 2>&1") != 0)
    cr_skip_test("no ninja or no make");
  static const char *const names[] = {"a\\ b.png", "c d.png", "e#f.png", "g$h.png",
                                      "i\\j.png",  "k*l.png", "m[n].png"};
  for (size_t i = 0; i < sizeof names / sizeof names[0]; i++) {
    char dir[16], path[64];
    snprintf(dir, sizeof dir, "d%zu", i);
    const char *cwd = tmp(dir);
    cr_assert_eq(mkdir(cwd, 0755), 0);
    snprintf(path, sizeof path, "%s/%s", dir, names[i]);
    height_file(tmp(path));
    cli_result r = RUN_IN(cwd, "bake", names[i], FAST, "--normal", "o.png", "--depfile", "o.d");
    if (r.code == 1 && strstr(r.err, "which a depfile cannot say")) {
      snprintf(path, sizeof path, "%s/o.png", dir);
      cr_expect(!file_exists(tmp(path)), "%s: refused, but the map was written", names[i]);
      cli_result_free(&r);
      continue;
    }
    cr_assert_eq(r.code, 0, "%s: %s", names[i], r.err);
    cli_result_free(&r);
    /* make: the output is up to date only if the input's name reads back. */
    char command[512];
    snprintf(command, sizeof command,
             "cd '%s' && printf 'include o.d\\n' >mk && make -q -f mk o.png >make.log 2>&1",
             cwd);
    cr_expect_eq(system(command), 0, "%s: make misreads the depfile", names[i]);
    /* ninja: a rule whose depfile is this one; -t deps lists what it read. */
    snprintf(command, sizeof command,
             "cd '%s' && mv o.d o.d.src && printf 'rule r\\n  command = cp o.d.src o.d && "
             "touch o.png\\n  depfile = o.d\\n  deps = gcc\\nbuild o.png: r\\n' >build.ninja "
             "&& ninja >ninja.log 2>&1 && ninja -t deps o.png >deps.log 2>&1",
             cwd);
    cr_assert_eq(system(command), 0, "%s: ninja failed", names[i]);
    snprintf(path, sizeof path, "%s/deps.log", dir);
    size_t size;
    char *deps = (char *)slurp_file(tmp(path), &size);
    char want[64];
    snprintf(want, sizeof want, "\n    %s\n", names[i]);
    cr_expect(strstr(deps, want), "%s: ninja read %s", names[i], deps);
    free(deps);
  }
}

/* ---------------------------------------------------------------- programs */

/* A program's images stay inside --base unless --allow-outside-base. */
Test(hostile, program_images_stay_inside_the_base) {
  cr_assert_eq(mkdir(tmp("base"), 0755), 0);
  height_file(tmp("outside.png"));
  height_file(tmp("base/inside.png"));
  cr_assert_eq(symlink(tmp("outside.png"), tmp("base/link.png")), 0);
  const char *up[] = {"program", "invertColor(../outside.png)", "--base", tmp("base"), "-o",
                      tmp("o.png"), NULL};
  harness_expect_refusal(NULL, up, 1, "outside the base directory", 11);
  const char *absolute[] = {"program", "invertColor(/etc/passwd)", "--base", tmp("base"),
                            "-o", tmp("o.png"), NULL};
  harness_expect_refusal(NULL, absolute, 1, "an absolute path", 12);
  const char *link[] = {"program", "invertColor(link.png)", "--base", tmp("base"), "-o",
                        tmp("o.png"), NULL};
  harness_expect_refusal(NULL, link, 1, "outside the base directory", 13);
  cr_expect(!file_exists(tmp("o.png")));
  const char *inside[] = {"program", "invertColor(inside.png)", "--base", tmp("base"), "-o",
                          tmp("o.png"), NULL};
  cli_result r = harness_run(inside);
  cr_expect_eq(r.code, 0, "%s", r.err);
  cli_result_free(&r);
  const char *allowed[] = {"program", "invertColor(../outside.png)", "--base", tmp("base"),
                           "--allow-outside-base", "-o", tmp("o2.png"), NULL};
  r = harness_run(allowed);
  cr_expect_eq(r.code, 0, "%s", r.err);
  cli_result_free(&r);
}

/* ---------------------------------------------------- what it prints */

/* A description holding an escape sequence and a byte that is not UTF-8,
 * and a file name with both: info, compare and errors print them escaped,
 * and --json stays valid UTF-8. */
Test(hostile, printed_text_never_drives_the_terminal) {
  bb_image img;
  cr_assert_eq(bb_image_alloc(&img, 4, 4, 1, NULL), BB_OK);
  const bb_write_options wo = {BB_DEPTH_8, BB_RANGE_UNIT,
                               "bumpbake_version=x\ncommand=\x1b]0;pwned\x07\x1b[31mred\xff\n", NULL};
  cr_assert_eq(bb__image_write(tmp("e.png"), &img, &wo, NULL), BB_OK);
  const char *name = "bad\x1b[2J\xff.png";
  cr_assert_eq(bb__image_write(tmp(name), &img, &wo, NULL), BB_OK);
  bb_image_free(&img);
  const char *runs[][6] = {{"info", tmp("e.png"), NULL},
                           {"info", tmp(name), NULL},
                           {"compare", tmp("e.png"), tmp(name), NULL},
                           {"bake", tmp(name), "--ao", tmp("x.jpg"), NULL},
                           {"info", tmp("missing\x1b[31m.png"), NULL}};
  for (size_t i = 0; i < sizeof runs / sizeof runs[0]; i++) {
    cli_result r = harness_run(runs[i]);
    cr_expect(!has_control(r.out), "%s stdout carries control bytes", runs[i][0]);
    cr_expect(!has_control(r.err), "%s stderr carries control bytes", runs[i][0]);
    cli_result_free(&r);
  }
  const char *json[] = {"info", "--json", tmp(name), NULL};
  cli_result r = harness_run(json);
  cr_expect_eq(r.code, 0, "%s", r.err);
  cr_expect(valid_utf8(r.out), "info --json is not UTF-8: %s", r.out);
  cr_expect(strstr(r.out, "\\udcff"), "the 0xff byte is not \\udcff: %s", r.out);
  cr_expect(strstr(r.out, "\\u001b"), "ESC is not escaped: %s", r.out);
  cli_result_free(&r);
}

/* Bidirectional controls from a file (U+202E in a VTF's KVD, U+2066 in a
 * PNG's description, U+200E in a file name) were printed raw, while C0
 * and C1 were escaped: they reorder what a terminal shows. They are
 * escaped by the same rule (bb_text_printable), byte by byte. */
Test(hostile, bidirectional_controls_from_a_file_are_escaped) {
  bb_image img;
  cr_assert_eq(bb_image_alloc(&img, 4, 4, 3, NULL), BB_OK);
  bb_texture_options t;
  bb_texture_options_init(&t);
  t.vtf_version = 3;
  t.format = BB_TEXTURE_FORMAT_BGR8;
  t.description = "bumpbake_version=x\ncommand=a\xe2\x80\xaegnp.exe\n";
  bb_error err = {{0}};
  cr_assert_eq(bb__texture_write(tmp("k.vtf"), &img, &t, &err), BB_OK, "%s", err.message);
  const bb_write_options wo = {BB_DEPTH_8, BB_RANGE_UNIT,
                               "a\xe2\x81\xa6" "b\xe2\x81\xa9 \xd8\x9c \xe2\x80\x8f\xe2\x80\xaa", NULL};
  const char *name = "n\xe2\x80\x8e.png";
  cr_assert_eq(bb__image_write(tmp("d.png"), &img, &wo, NULL), BB_OK);
  cr_assert_eq(bb__image_write(tmp(name), &img, &wo, NULL), BB_OK);
  bb_image_free(&img);
  const char *runs[][4] = {{"info", tmp("k.vtf"), NULL},
                           {"info", tmp("d.png"), NULL},
                           {"info", tmp(name), NULL},
                           {"info", tmp("gone\xe2\x80\xae.png"), NULL}};
  const char *shown[] = {"a\\xe2\\x80\\xaegnp.exe", "a\\xe2\\x81\\xa6b", "n\\xe2\\x80\\x8e.png",
                         "gone\\xe2\\x80\\xae.png"};
  for (size_t i = 0; i < sizeof runs / sizeof runs[0]; i++) {
    cli_result r = harness_run(runs[i]);
    cr_expect(!has_control(r.out) && !has_control(r.err), "info %zu printed a control: %s%s", i,
              r.out, r.err);
    cr_expect(strstr(r.out, shown[i]) || strstr(r.err, shown[i]), "info %zu lacks %s: %s%s", i,
              shown[i], r.out, r.err);
    cli_result_free(&r);
  }
  /* The rule itself: what it escapes, and what it leaves (accents, CJK). */
  char out[256];
  cr_expect_str_eq(bb_text_printable("\xd8\x9c|\xe2\x80\x8f|\xe2\x80\xaa|\xe2\x81\xa9|\x1b|\xc2\x9b|\xff",
                                     out, sizeof out),
                   "\\xd8\\x9c|\\xe2\\x80\\x8f|\\xe2\\x80\\xaa|\\xe2\\x81\\xa9|\\x1b|\\xc2\\x9b|\\xff");
  cr_expect_str_eq(bb_text_printable("h\xc3\xa9ight \xe9\xab\x98\xe3\x81\x95 \xe2\x80\x94 \xe2\x80\xaf",
                                     out, sizeof out),
                   "h\xc3\xa9ight \xe9\xab\x98\xe3\x81\x95 \xe2\x80\x94 \xe2\x80\xaf");
  cr_expect_str_eq(bb_text_printable("ab\xe2\x80\xae", out, 8), "ab", "a control cut short");
}

/* The other text a file brings: a basis file's line and a program's text
 * in error messages, and a batch's "wrote" lines of a name holding an
 * escape sequence (all printed raw before). */
Test(hostile, basis_lines_program_text_and_batch_names_are_printed_escaped) {
  height_file(tmp("h.png"));
  FILE *f = fopen(tmp("b.txt"), "w");
  cr_assert_not_null(f);
  fputs("0 0 1\n\x1b]0;pwned\x07\x1b[31m 1 0\n", f);
  cr_assert_eq(fclose(f), 0);
  cr_assert_eq(mkdir(tmp("in"), 0755), 0);
  height_file(tmp("in/bad\x1b[2J\xc2\x9b.png"));
  const char *runs[][16] = {
      {"bake", tmp("h.png"), FAST, "--basis", tmp("b.txt"), "--ssbump", tmp("o.png"), NULL},
      {"program", "invertColor(\x1b]0;pwned\x07\x1b[31m)", "-o", tmp("o.png"), NULL},
      {"bake", tmp("in"), FAST, "--out-dir", tmp("out"), "--maps", "normal", NULL},
  };
  const int codes[] = {1, 1, 0};
  for (size_t i = 0; i < sizeof runs / sizeof runs[0]; i++) {
    cli_result r = harness_run(runs[i]);
    cr_expect_eq(r.code, codes[i], "run %zu: exit %d: %s", i, r.code, r.err);
    cr_expect(!has_control(r.out), "run %zu: stdout carries control bytes: %s", i, r.out);
    cr_expect(!has_control(r.err), "run %zu: stderr carries control bytes: %s", i, r.err);
    if (i == 2)
      cr_expect(strstr(r.out, "wrote normal") && strstr(r.out, "\\x1b[2J\\xc2\\x9b"),
                "the wrote line: %s", r.out);
    cli_result_free(&r);
  }
}

/* A provenance key of 200 bytes and a value of 3022 bytes with a two-byte
 * character across byte 1023: --json cut keys at 127 and values at 1023
 * bytes, splitting the character (not UTF-8). Now both come whole. */
Test(hostile, json_keeps_long_keys_and_values_whole) {
  char key[201], value[3100], text[3400];
  memset(key, 'k', 200);
  key[200] = '\0';
  memset(value, 'v', 1022);
  memcpy(value + 1022, "\xc3\xa9", 2); /* é at bytes 1022..1023 */
  memset(value + 1024, 'w', 2000);
  value[3024] = '\0';
  snprintf(text, sizeof text, "bumpbake_version=x\n%s=%s\n", key, value);
  bb_image img;
  cr_assert_eq(bb_image_alloc(&img, 4, 4, 1, NULL), BB_OK);
  const bb_write_options wo = {BB_DEPTH_8, BB_RANGE_UNIT, text, NULL};
  cr_assert_eq(bb__image_write(tmp("long.png"), &img, &wo, NULL), BB_OK);
  bb_image_free(&img);
  cli_result r = RUN("info", "--json", tmp("long.png"));
  cr_expect_eq(r.code, 0, "%s", r.err);
  cr_expect(valid_utf8(r.out), "info --json is not UTF-8");
  char want[3400];
  snprintf(want, sizeof want, "\"%s\":\"%s\"", key, value);
  cr_expect(strstr(r.out, want), "the key or the value was cut: %.300s...", r.out);
  cli_result_free(&r);
}

/* ------------------------------------------------------ address space */

/* The start-up minimum docs/limits.md gives for `bumpbake --version`, in
 * KiB; 0 when it gives none. */
static long documented_start_kib(void) {
  FILE *f = fopen("docs/limits.md", "r");
  if (!f)
    return 0;
  char line[512];
  long kib = 0;
  while (!kib && fgets(line, sizeof line, f)) {
    if (strncmp(line, "| `bumpbake --version` |", 24) != 0)
      continue;
    for (const char *c = line + 24; *c && *c != '('; c++)
      if (*c >= '0' && *c <= '9')
        kib = kib * 10 + (*c - '0');
  }
  fclose(f);
  return kib;
}

/* Below what OpenImageIO's and log4cplus's static constructors need the
 * process dies before main() (exit 127, 134 or 139), which is documented,
 * with its minimum; the minimum given must start. Every run that gets to
 * main(), from 430 MB to 1.6 GB, ends cleanly: exit 0, or exit 1 with one
 * line saying it is out of memory (or that the bake's estimate does not
 * fit what is available), nothing written (renderbumpflat said
 * "not a readable model: std::bad_alloc" at 460 and 470 MB before). */
Test(hostile, past_the_documented_start_up_minimum_every_run_ends_cleanly, .timeout = 600) {
#if defined(__SANITIZE_ADDRESS__)
  cr_skip_test("ASan reserves terabytes of address space");
#endif
  const long start_kib = documented_start_kib();
  cr_assert_gt(start_kib, 10000, "docs/limits.md gives no start-up minimum for --version");
  const run_limits at_minimum = {-1, start_kib * 1024};
  cli_result r = harness_run_limited(NULL, &at_minimum, (const char *const[]){"--version", NULL});
  cr_expect_eq(r.code, 0, "the documented minimum of %ld KiB does not start: exit %d", start_kib,
               r.code);
  cli_result_free(&r);
  height_file(tmp("h.png"));
  const char *fixtures = getenv("BB_FIXTURES");
  char model[512];
  snprintf(model, sizeof model, "%s/rivet_panel.obj", fixtures ? fixtures : "fixtures");
  cr_assert_eq(mkdir(tmp("out"), 0755), 0);
  const long limits_kib[] = {430000, 460000, 470000, start_kib + 8000, 500000,
                             540000, 600000,  800000, 1600000};
  for (size_t i = 0; i < sizeof limits_kib / sizeof limits_kib[0]; i++) {
    const run_limits lim = {-1, limits_kib[i] * 1024};
    const char *const runs[][16] = {
        {"bake", tmp("h.png"), FAST, "-o", tmp("out/r"), NULL},
        {"renderbumpflat", model, "--size", "128", "128", "-o", tmp("out/p.tga"), NULL},
    };
    for (size_t k = 0; k < 2; k++) {
      r = harness_run_limited(NULL, &lim, runs[k]);
      const int before_main = r.code == 127 || r.code == 134 || r.code == 139;
      if (before_main) {
        cr_expect_lt(limits_kib[i], start_kib, "%s at %ld KiB, over the documented minimum: "
                     "exit %d: %s", runs[k][0], limits_kib[i], r.code, r.err);
      } else if (r.code != 0) {
        cr_expect_eq(r.code, 1, "%s at %ld KiB: exit %d: %s", runs[k][0], limits_kib[i], r.code,
                     r.err);
        cr_expect_eq(harness_lines(r.err), 1, "%s at %ld KiB: %s", runs[k][0], limits_kib[i],
                     r.err);
        /* An allocation that failed, or the bake's estimate refused first. */
        cr_expect(strstr(r.err, "out of memory") || strstr(r.err, " of memory; "),
                  "%s at %ld KiB: %s", runs[k][0], limits_kib[i], r.err);
        DIR *d = opendir(tmp("out"));
        cr_assert_not_null(d);
        int entries = 0;
        for (struct dirent *e; (e = readdir(d));)
          entries += e->d_name[0] != '.' || strncmp(e->d_name, ".bb-tmp", 7) == 0;
        closedir(d);
        cr_expect_eq(entries, 0, "%s at %ld KiB failed but left files", runs[k][0],
                     limits_kib[i]);
      }
      cli_result_free(&r);
      char command[1024];
      snprintf(command, sizeof command, "rm -rf '%s'/* '%s'/.bb-tmp*", tmp("out"), tmp("out"));
      cr_assert_eq(system(command), 0);
    }
  }
}
