/* test_animation.c: the animated GIF writer: frames, checks, and no file
 * left behind on failure. */
#define _XOPEN_SOURCE 700 /* mkdtemp */

#include <criterion/criterion.h>

#include <dirent.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "bumpbake.h"
#include "image/oiio.h"

static char dir[64];

static void make_dir(void) {
  snprintf(dir, sizeof dir, "/tmp/bb_anim_XXXXXX");
  cr_assert_not_null(mkdtemp(dir));
}

/* Number of entries in dir (temporary files included), then removes them. */
static int entries_then_clean(void) {
  DIR *d = opendir(dir);
  cr_assert_not_null(d);
  int n = 0;
  struct dirent *e;
  char path[512];
  while ((e = readdir(d)))
    if (strcmp(e->d_name, ".") && strcmp(e->d_name, "..")) {
      n++;
      snprintf(path, sizeof path, "%s/%s", dir, e->d_name);
      unlink(path);
    }
  closedir(d);
  rmdir(dir);
  return n;
}

static bb_image frame(int width, int height, float v) {
  bb_image img;
  cr_assert_eq(bb_image_alloc(&img, width, height, 3, NULL), BB_OK);
  for (int i = 0; i < width * height * 3; i++)
    img.pixels[i] = v * (float)(i % 7) / 6.0f;
  return img;
}

Test(animation, frames_written_and_counted) {
  make_dir();
  char path[128];
  snprintf(path, sizeof path, "%s/orbit.gif", dir);
  bb_animation *a = NULL;
  bb_error err = {{0}};
  cr_assert_eq(bb__animation_open(path, 9, 7, 10.0, &a, &err), BB_OK, "%s", err.message);
  for (int f = 0; f < 4; f++) {
    bb_image img = frame(9, 7, 0.25f * (float)(f + 1));
    cr_assert_eq(bb__animation_add_frame(a, &img, &err), BB_OK, "%s", err.message);
    bb_image_free(&img);
  }
  cr_assert_eq(access(path, F_OK), -1, "nothing at the final name before close");
  cr_assert_eq(bb__animation_close(a, &err), BB_OK, "%s", err.message);
  int frames = 0;
  cr_assert_eq(bb__image_frame_count(path, &frames, &err), BB_OK, "%s", err.message);
  cr_assert_eq(frames, 4);
  bb_image back;
  cr_assert_eq(bb_image_read(path, &back, NULL, NULL), BB_OK);
  cr_assert_eq(back.width, 9);
  cr_assert_eq(back.height, 7);
  bb_image_free(&back);
  cr_assert_eq(entries_then_clean(), 1, "only orbit.gif: no temporary file left");
}

Test(animation, failures_leave_no_file) {
  make_dir();
  char path[128];
  snprintf(path, sizeof path, "%s/bad.gif", dir);
  bb_animation *a = NULL;
  bb_error err = {{0}};
  cr_assert_eq(bb__animation_open(path, 8, 8, 10.0, &a, &err), BB_OK);
  bb_image wrong = frame(8, 9, 1.0f);
  cr_assert_eq(bb__animation_add_frame(a, &wrong, &err), BB_ERR_ARGUMENT);
  bb_image_free(&wrong);
  cr_assert_eq(bb__animation_close(a, &err), BB_ERR_ARGUMENT, "no frame was added");
  cr_assert(strstr(err.message, "no frames"), "%s", err.message);
  cr_assert_eq(bb__animation_open(path, 8, 8, 10.0, &a, &err), BB_OK);
  bb_image ok = frame(8, 8, 1.0f);
  cr_assert_eq(bb__animation_add_frame(a, &ok, &err), BB_OK);
  bb_image_free(&ok);
  bb__animation_abort(a);
  bb__animation_abort(NULL);
  char png[128];
  snprintf(png, sizeof png, "%s/x.png", dir);
  cr_assert_eq(bb__animation_open(png, 8, 8, 10.0, &a, &err), BB_ERR_FORMAT);
  cr_assert_eq(bb__animation_open(path, 8, 8, 0.5, &a, &err), BB_ERR_ARGUMENT);
  cr_assert_eq(bb__animation_open("/nonexistent-dir/a.gif", 8, 8, 10.0, &a, &err),
               BB_ERR_IO);
  cr_assert_null(a);
  cr_assert_eq(entries_then_clean(), 0, "nothing left behind");
}
