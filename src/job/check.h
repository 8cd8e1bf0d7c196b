/* check.h: what the golden check's files share (not public): a check's
 * setup, as the command planned it, its cases with their strings and the
 * report's pictures, and the steps one case goes through (check.c decides,
 * check_bake.c bakes, check_pictures.c draws, check_report.c reports). */
#ifndef BB_JOB_CHECK_H
#define BB_JOB_CHECK_H

#include "bumpbake.h"

#include <stddef.h>

/* The fields of bb_compare_limits a rule sets (bb__check_rule.given). */
enum {
  BB__LIMIT_FAIL = 1u << 0,
  BB__LIMIT_FAIL_PERCENT = 1u << 1,
  BB__LIMIT_HARD_FAIL = 1u << 2,
  BB__LIMIT_ALLOW_FAILURES = 1u << 3,
  BB__LIMIT_WARN = 1u << 4,
  BB__LIMIT_WARN_PERCENT = 1u << 5,
  BB__LIMIT_HARD_WARN = 1u << 6
};

/* One rule of --limits: the limits it sets for the maps it selects. */
typedef struct bb__check_rule {
  char *selector;           /* a map kind's name, or a pattern of names */
  int is_kind;              /* 1: selector is a kind ("ao"), 0: a pattern
                               (fnmatch, '*' crossing '/', "*_normal.png") */
  bb_compare_limits limits; /* its values, where given */
  unsigned given;           /* BB__LIMIT_* */
} bb__check_rule;

/* A check as the command planned it (cmd/run_check.c). */
typedef struct bb__check_setup {
  const char *golden;       /* the golden directory (or file) */
  const char *fresh;        /* the new directory (or file); NULL: a bake */
  bb_job *job;              /* a bake's batch (out_dir = golden), planned
                               read-only unless update; the check takes it */
  bb_compare_limits limits; /* idiff's options as given */
  bb__check_rule *rules;    /* --limits, in order; the check takes them */
  int rule_count;
  int update;               /* write the goldens of cases that do not pass */
  const char *junit, *html; /* the reports' paths, or NULL */
  int json, quiet;          /* how its lines print */
  int threads;              /* for writing pictures, 0: all cores */
} bb__check_setup;

/* A check: its setup (strings its own copies), its cases in the order
 * decided, and the report's atlas being filled. */
typedef struct bb__check_atlas bb__check_atlas;
struct bb_check {
  bb__check_setup setup;
  char *golden, *fresh, *junit, *html;
  struct bb__check_case **cases;
  int count, capacity;
  bb__check_atlas *atlas;
};

/* A check from setup (copied; its job and rules taken, freed on failure
 * too). */
bb_status bb__check_new(bb__check_setup *setup, bb_check **out, bb_error *err);

/* The limits of a map of kind (may be "") named name: idiff's options as
 * given, then every rule that selects it, in order. */
bb_compare_limits bb__check_limits(const bb_check *check, const char *kind,
                                   const char *name);

/* --------------------------------------------------------------- cases */

/* A case as the check keeps it: the public record, its strings, and its
 * pictures in the HTML report. */
typedef struct bb__check_case {
  bb_check_case pub;
  char *name, *golden, *fresh, *kind, *provenance_diff, *message, *update_error;
  char *thumbs;   /* the thumbnail's atlas, relative to the report */
  int thumb_cell; /* its cell in the atlas */
  int thumb_width, thumb_height;
  char *strip; /* golden | new | difference, relative, or NULL */
  int strip_width, strip_height, strip_parts; /* one part's size, and how many */
  double heat_max; /* the difference the heat map's white stands for */
} bb__check_case;

/* What deciding a case is given: the two images as read (either may be
 * NULL: MISSING, EXTRA, UNREADABLE) and their provenance texts, whether
 * each holds raw signed values (a float file of a normal map) for the
 * pictures, and a reason when status is decided already. */
typedef struct bb__check_sides {
  const bb_image *golden, *fresh;
  const char *golden_text, *fresh_text;
  int golden_signed, fresh_signed;
} bb__check_sides;

/* A new case named name (strings copied; fresh may be NULL), pending; NULL
 * when out of memory. */
bb__check_case *bb__check_case_new(const char *name, const char *golden,
                                   const char *fresh, const char *kind);
void bb__check_case_free(bb__check_case *k);

/* Decides k from sides under its limits (chosen here from its kind and
 * name): the statistics, the verdict, the provenance differences, and the
 * report's pictures. status BB_CHECK_PASS asks for the comparison; any
 * other is kept with message. Returns BB_OK, or the error of drawing its
 * pictures, BB_ERR_MEMORY. */
bb_status bb__check_decide(bb_check *check, bb__check_case *k,
                           const bb__check_sides *sides, bb_check_status status,
                           const char *message, bb_error *err);

/* Adds k to the check's cases (taking it, freed on failure too) and calls
 * each with it. */
bb_status bb__check_add(bb_check *check, bb__check_case *k, bb_check_case_fn each,
                        void *user, bb_error *err);

/* Why the link at path is not followed (it leads out of the tree whose
 * real path is real_root, to nothing, or to no regular file), or NULL; and
 * root's real path into out (PATH_MAX bytes), NULL when it has none. */
const char *bb__check_link_refusal(const char *real_root, const char *path);
const char *bb__check_real_root(const char *root, char *out);

/* What the check was set up with. */
const bb__check_setup *bb__check_setup_of(const bb_check *check);
bb_job *bb__check_job(bb_check *check);

/* -------------------------------------------------------- pictures */

/* The report's pictures of a case (check_pictures.c): its thumbnail in the
 * current atlas (the new map, else the golden), and for a case that does not
 * pass a strip of golden, new and their difference's heat map (golden and
 * new only when their sizes differ). The atlases are written as they fill
 * and by bb__check_pictures_flush. */
enum {
  BB__CHECK_THUMB = 64,     /* a thumbnail's cell in an atlas, in pixels */
  BB__CHECK_ATLAS_SIDE = 16 /* cells per row and column of an atlas */
};
bb_status bb__check_pictures(bb__check_atlas **atlas, const char *report_dir,
                             bb__check_case *k, const bb__check_sides *sides,
                             bb_error *err);
bb_status bb__check_pictures_flush(bb__check_atlas **atlas, bb_error *err);
void bb__check_atlas_free(bb__check_atlas *atlas);
/* Removes the pictures in the report's folder (by the names this file
 * gives them) that no case of cases[0..count-1] shows: an earlier run's. */
void bb__check_pictures_prune(const char *report_dir, bb__check_case *const *cases,
                              int count);

/* 1 when relative is a name this file gives a picture ("img/t-HASH.png",
 * "img/c-HASH.png"). */
int bb__check_picture_path(const char *relative);

/* -------------------------------------------------------- reports */

/* A case's text for a report (malloc'd; NULL when out of memory): what it
 * found in one line ("max abs error 0.01 at (3, 4) channel 1, ...", the
 * sizes, why it could not be read), then its provenance differences and
 * why its update failed, a line each. */
char *bb__check_case_text(const bb_check_case *k);

/* The JUnit XML file and the HTML report of cases[0..count-1]
 * (check_report.c), each written all or nothing. */
bb_status bb__check_junit(const char *path, const char *suite,
                          bb__check_case *const *cases, int count, bb_error *err);
bb_status bb__check_html(const char *dir, const char *title, bb__check_case *const *cases,
                         int count, bb_error *err);

#endif /* BB_JOB_CHECK_H */
