/* test_incremental.c: bb_file_hash, bb__bake_rayset_id and bb__output_check:
 * an output is current only when its provenance, depth and mip levels are
 * what writing it now would give. */
#define _XOPEN_SOURCE 700 /* mkdtemp, nftw, realpath */
#define _DEFAULT_SOURCE    /* wait4 (cli_harness.h) */

#include "bake/bake_internal.h"
#include "job/bake_rows.h"
#include "bumpbake.h"
#include "cli_harness.h"
#include "image/image_write.h"
#include "image/oiio.h"
#include "job/job_internal.h"
#include "trace/basis.h"

#include <stdio.h>

TestSuite(incremental, .init = harness_setup, .fini = harness_teardown, .timeout = 300);

/* FNV-1a 64's published values: "" and "a", and a file larger than the
 * 64 KiB block agrees with a one-shot hash of its bytes. */
Test(incremental, file_hash_is_fnv1a_of_the_bytes) {
  uint64_t h = 0;
  write_bytes(tmp("empty"), "", 0);
  cr_assert_eq(bb_file_hash(tmp("empty"), &h, NULL), BB_OK);
  cr_expect_eq(h, 0xcbf29ce484222325ULL);
  write_bytes(tmp("a"), "a", 1);
  cr_assert_eq(bb_file_hash(tmp("a"), &h, NULL), BB_OK);
  cr_expect_eq(h, 0xaf63dc4c8601ec8cULL);

  enum { N = 200000 };
  static char big[N];
  uint64_t want = 0xcbf29ce484222325ULL;
  for (int i = 0; i < N; i++) {
    big[i] = (char)(i * 7 + i / 251);
    want = (want ^ (unsigned char)big[i]) * 0x100000001b3ULL;
  }
  write_bytes(tmp("big"), big, N);
  cr_assert_eq(bb_file_hash(tmp("big"), &h, NULL), BB_OK);
  cr_expect_eq(h, want);
}

Test(incremental, file_hash_refuses_missing_files_and_directories) {
  uint64_t h = 1;
  bb_error err;
  cr_expect_eq(bb_file_hash(tmp("nothing"), &h, &err), BB_ERR_IO);
  cr_expect(strstr(err.message, "nothing"), "%s", err.message);
  cr_expect_eq(h, 0);
  cr_expect_eq(bb_file_hash(harness_dir, &h, &err), BB_ERR_IO);
  cr_expect(strstr(err.message, "cannot read: is a directory"), "%s", err.message);
}

/* A file that cannot be opened says "cannot read" once (a batch printed
 * "h.png: cannot read: cannot read: Permission denied"). As root the
 * check runs in a child that has given up root. */
Test(incremental, file_hash_says_cannot_read_once) {
  write_bytes(tmp("locked"), "x", 1);
  cr_assert_eq(chmod(tmp("locked"), 0), 0);
  const pid_t pid = fork();
  cr_assert(pid >= 0);
  if (pid == 0) {
    if (geteuid() == 0 && (setgid(65534) != 0 || setuid(65534) != 0))
      _exit(3);
    uint64_t h = 1;
    bb_error err = {{0}};
    if (bb_file_hash(tmp("locked"), &h, &err) != BB_ERR_IO)
      _exit(4);
    if (strstr(err.message, "cannot read: cannot read"))
      _exit(1);
    _exit(strstr(err.message, ": cannot read: Permission denied") ? 0 : 2);
  }
  int status = 0;
  cr_assert_eq(waitpid(pid, &status, 0), pid);
  cr_expect(WIFEXITED(status) && WEXITSTATUS(status) == 0,
            "child: %d (1: prefix repeated, 2: other words, 3: setuid, 4: no error)",
            WIFEXITED(status) ? WEXITSTATUS(status) : -1);
}

/* The id is the one bb__bake_checked records, without building anything. */
Test(incremental, rayset_id_is_the_bakes) {
  bb_image h;
  cr_assert_eq(bb_image_alloc(&h, 8, 8, 1, NULL), BB_OK);
  bb_bake_options o;
  bb__bake_options_init(&o);
  o.height_scale = 2.0f;
  o.rays = 40;
  o.power = 2.5;
  cr_assert_eq(bb__basis_parse("dirs:5", &o.basis, NULL), BB_OK);
  bb_bake_result r;
  cr_assert_eq(bb__bake_checked(&h, &o, &r, NULL), BB_OK);
  char id[64];
  bb__bake_rayset_id(&o, id, sizeof id);
  cr_expect_str_eq(id, r.rayset_id);
  o.slices = 9;
  bb__bake_rayset_id(&o, id, sizeof id);
  cr_expect_str_eq(id, "bb-horizon-v1:a9:p2.5:dirs:5");
  o.outputs = BB_MAP_BIT(BB_MAP_NORMAL);
  bb__bake_rayset_id(&o, id, sizeof id);
  cr_expect_str_eq(id, "");
  bb_bake_result_free(&r);
  bb_image_free(&h);
}

/* ------------------------------------------------------------ the check */

typedef struct fixture {
  bb_bake_options options;
  bb_provenance p;
} fixture;

static void fixture_init(fixture *f) {
  bb__bake_options_init(&f->options);
  f->options.height_scale = 8.0f;
  f->p = (bb_provenance){"bumpbake bake a.png --scale 8", "a.png", 0x1234, "normal",
                         &f->options, BB_CHANNEL_AUTO, "bb-horizon-v1:a16:p1:hl2",
                         0xfeedULL, NULL};
}

/* An image written with the given description. */
static void write_output(const char *path, const char *description, bb_depth depth) {
  bb_image img;
  cr_assert_eq(bb_image_alloc(&img, 4, 4, 3, NULL), BB_OK);
  bb_write_options wo = {depth, BB_RANGE_SIGNED, description, NULL};
  bb_error err;
  cr_assert_eq(bb__image_write(path, &img, &wo, &err), BB_OK, "%s", err.message);
  bb_image_free(&img);
}

static void write_described(const char *path, const bb_provenance *p, bb_depth depth) {
  char *text = bb__provenance_format(p);
  cr_assert_not_null(text);
  write_output(path, text, depth);
  free(text);
}

static bb_output_state check(const char *path, const bb_provenance *p, bb_depth depth,
                             int mips, char *reason, size_t cap) {
  bb_output_state state = BB_OUTPUT_CURRENT;
  bb_error err;
  cr_assert_eq(bb__output_check(path, p, depth, mips, &state, reason, cap, &err), BB_OK, "%s",
               err.message);
  return state;
}

Test(incremental, an_output_written_as_described_is_current) {
  fixture f;
  fixture_init(&f);
  write_described(tmp("n.png"), &f.p, BB_DEPTH_DEFAULT);
  char reason[256];
  cr_expect_eq(check(tmp("n.png"), &f.p, BB_DEPTH_DEFAULT, 0, reason, sizeof reason),
               BB_OUTPUT_CURRENT, "%s", reason);
  cr_expect_str_empty(reason);
  cr_expect_eq(check(tmp("n.png"), &f.p, BB_DEPTH_8, 0, reason, sizeof reason),
               BB_OUTPUT_CURRENT, "8-bit is PNG's default: %s", reason);
  /* The command line, the input's name and the decoded hash do not count. */
  bb_provenance moved = f.p;
  moved.command = "bumpbake bake elsewhere/a.png --scale 8 --threads 1";
  moved.input_name = "renamed.png";
  moved.input_hash = 99;
  cr_expect_eq(check(tmp("n.png"), &moved, BB_DEPTH_DEFAULT, 0, NULL, 0), BB_OUTPUT_CURRENT);
}

Test(incremental, a_changed_parameter_input_or_kind_is_stale) {
  fixture f;
  fixture_init(&f);
  write_described(tmp("n.png"), &f.p, BB_DEPTH_DEFAULT);
  char reason[256];

  bb_bake_options other = f.options;
  other.height_scale = 16.0f;
  bb_provenance p = f.p;
  p.options = &other;
  cr_expect_eq(check(tmp("n.png"), &p, BB_DEPTH_DEFAULT, 0, reason, sizeof reason),
               BB_OUTPUT_STALE);
  cr_expect_str_eq(reason, "scale: 8 -> 16");

  p = f.p;
  p.input_file_hash = 0xbeefULL;
  cr_expect_eq(check(tmp("n.png"), &p, BB_DEPTH_DEFAULT, 0, reason, sizeof reason),
               BB_OUTPUT_STALE);
  cr_expect_str_eq(reason, "input_file_hash: 000000000000feed -> 000000000000beef");

  p = f.p;
  p.output_kind = "ao";
  cr_expect_eq(check(tmp("n.png"), &p, BB_DEPTH_DEFAULT, 0, NULL, 0), BB_OUTPUT_STALE);
  /* A normal map does not depend on the trace: another ray set or ray
   * count leaves it current; an ssbump's are stale. */
  p = f.p;
  p.rayset_id = NULL;
  bb_bake_options fewer = f.options;
  fewer.rays = 64;
  p.options = &fewer;
  cr_expect_eq(check(tmp("n.png"), &p, BB_DEPTH_DEFAULT, 0, reason, sizeof reason),
               BB_OUTPUT_CURRENT, "%s", reason);
  bb_provenance ssbump = f.p;
  ssbump.output_kind = "ssbump";
  write_described(tmp("s.png"), &ssbump, BB_DEPTH_DEFAULT);
  ssbump.rayset_id = NULL;
  cr_expect_eq(check(tmp("s.png"), &ssbump, BB_DEPTH_DEFAULT, 0, reason, sizeof reason),
               BB_OUTPUT_STALE);
  cr_expect(strstr(reason, "rayset:"), "%s", reason);
  p = f.p;
  p.channel = BB_CHANNEL_A;
  cr_expect_eq(check(tmp("n.png"), &p, BB_DEPTH_DEFAULT, 0, NULL, 0), BB_OUTPUT_STALE);
  /* Without the input file's hash nothing can be known current. */
  p = f.p;
  p.input_file_hash = 0;
  cr_expect_eq(check(tmp("n.png"), &p, BB_DEPTH_DEFAULT, 0, reason, sizeof reason),
               BB_OUTPUT_STALE);
  cr_expect(strstr(reason, "hash is not known"), "%s", reason);
}

/* Another version, a key the expected text lacks (another producer's
 * parameters), no provenance or a missing file: not current. */
Test(incremental, other_versions_extra_keys_and_missing_files_are_not_current) {
  fixture f;
  fixture_init(&f);
  char *text = bb__provenance_format(&f.p), reason[256];
  cr_assert_not_null(text);
  char old[2048];
  snprintf(old, sizeof old, "bumpbake_version=0.0.1\n%s", strchr(text, '\n') + 1);
  write_output(tmp("old.png"), old, BB_DEPTH_DEFAULT);
  cr_expect_eq(check(tmp("old.png"), &f.p, BB_DEPTH_DEFAULT, 0, reason, sizeof reason),
               BB_OUTPUT_STALE);
  cr_expect_str_eq(reason, "bumpbake_version: 0.0.1 -> " BB_VERSION_STRING);

  char extra[2048];
  snprintf(extra, sizeof extra, "%saxis=+y\n", text);
  write_output(tmp("extra.png"), extra, BB_DEPTH_DEFAULT);
  cr_expect_eq(check(tmp("extra.png"), &f.p, BB_DEPTH_DEFAULT, 0, reason, sizeof reason),
               BB_OUTPUT_STALE);
  cr_expect_str_eq(reason, "axis: +y -> (none)");

  write_output(tmp("bare.png"), NULL, BB_DEPTH_DEFAULT);
  cr_expect_eq(check(tmp("bare.png"), &f.p, BB_DEPTH_DEFAULT, 0, reason, sizeof reason),
               BB_OUTPUT_STALE);
  cr_expect_str_eq(reason, "no bumpbake provenance");

  cr_expect_eq(check(tmp("none.png"), &f.p, BB_DEPTH_DEFAULT, 0, reason, sizeof reason),
               BB_OUTPUT_MISSING);
  write_bytes(tmp("junk.png"), "junk", 4);
  cr_expect_eq(check(tmp("junk.png"), &f.p, BB_DEPTH_DEFAULT, 0, NULL, 0), BB_OUTPUT_STALE);
  free(text);
}

/* The file's depth and mip levels are part of what was asked. */
Test(incremental, depth_and_mip_levels_must_match) {
  fixture f;
  fixture_init(&f);
  char reason[256];
  write_described(tmp("n.png"), &f.p, BB_DEPTH_DEFAULT);
  cr_expect_eq(check(tmp("n.png"), &f.p, BB_DEPTH_16, 0, reason, sizeof reason),
               BB_OUTPUT_STALE);
  cr_expect_str_eq(reason, "8-bit samples; 16-bit asked");
  write_described(tmp("n.exr"), &f.p, BB_DEPTH_HALF);
  cr_expect_eq(check(tmp("n.exr"), &f.p, BB_DEPTH_HALF, 0, NULL, 0), BB_OUTPUT_CURRENT);
  cr_expect_eq(check(tmp("n.exr"), &f.p, BB_DEPTH_DEFAULT, 0, reason, sizeof reason),
               BB_OUTPUT_STALE);
  cr_expect_str_eq(reason, "half float samples; float asked");
  cr_expect_eq(check(tmp("n.exr"), &f.p, BB_DEPTH_HALF, 1, reason, sizeof reason),
               BB_OUTPUT_STALE);
  cr_expect_str_eq(reason, "one level; mip-mapped asked");
}

Test(incremental, bad_arguments) {
  fixture f;
  fixture_init(&f);
  bb_output_state state;
  bb_error err;
  cr_expect_eq(bb__output_check(NULL, &f.p, BB_DEPTH_DEFAULT, 0, &state, NULL, 0, &err),
               BB_ERR_ARGUMENT);
  cr_expect_eq(bb__output_check(tmp("x.png"), NULL, BB_DEPTH_DEFAULT, 0, &state, NULL, 0, &err),
               BB_ERR_ARGUMENT);
  cr_expect_eq(bb__output_check(tmp("x.png"), &f.p, (bb_depth)9, 0, &state, NULL, 0, &err),
               BB_ERR_ARGUMENT);
}

Test(incremental, readable_formats_by_extension) {
  cr_expect(bb__path_is_readable_format("a.png"));
  cr_expect(bb__path_is_readable_format("dir.d/A.TIF"));
  cr_expect(bb__path_is_readable_format("x.exr"));
  cr_expect(bb__path_is_readable_format("x.jpg"));
  cr_expect(!bb__path_is_readable_format("notes.txt"));
  cr_expect(!bb__path_is_readable_format("Makefile"));
  cr_expect(!bb__path_is_readable_format("x.d"));
  cr_expect(!bb__path_is_readable_format(NULL));
}

/* An input whose header is refused is not current, and the check says the
 * refusal rather than failing: a batch's check of every input first (Python
 * on a cluster) then bakes the others, and the bake reports that one. A
 * missing input is still an error. */
Test(incremental, an_input_that_is_no_image_is_not_current) {
  cr_assert_eq(mkdir(tmp("in"), 0755), 0);
  write_bytes(tmp("in/bad.png"), "\x89PNG\r\n\x1a\n not really", 20);
  bb_image h;
  cr_assert_eq(bb_image_alloc(&h, 8, 8, 1, NULL), BB_OK);
  harness_write(tmp("in/good.png"), &h, BB_DEPTH_8, BB_RANGE_UNIT);
  bb_image_free(&h);
  bb_job_options o;
  bb__job_options_init(&o);
  o.command = "bumpbake bake (a test of the job)"; /* a plan records a line */
  o.bake.height_scale = 4.0f;
  o.out_dir = tmp("out");
  o.maps = BB_MAP_BIT(BB_MAP_NORMAL);
  const char *inputs[] = {tmp("in")};
  bb_job *job = NULL;
  bb_error err = {{0}};
  cr_assert_eq(bb__job_plan_options(inputs, 1, &o, &job, &err), BB_OK, "%s", err.message);
  cr_assert_eq(bb_job_count(job), 2);
  int current = 1;
  cr_expect_eq(bb_job_check_current(job, 0, &current, &err), BB_OK, "%s", err.message);
  cr_expect_eq(current, 0);
  const char *reason = bb_job_report_get(job, 0)->reason;
  cr_expect(strstr(reason, "bad.png") && strstr(reason, "not a readable image"), "%s", reason);
  cr_expect_eq(bb_job_check_current(job, 1, &current, &err), BB_OK, "%s", err.message);
  cr_expect_eq(current, 0);
  cr_assert_eq(unlink(tmp("in/good.png")), 0);
  cr_expect_eq(bb_job_check_current(job, 1, &current, &err), BB_ERR_IO);
  bb_job_free(job);
}
