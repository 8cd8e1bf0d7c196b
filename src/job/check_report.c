/* check_report.c: a golden check's reports. JUnit XML for CI servers (GitLab,
 * Jenkins and GitHub's test reporters read it): a test case per map, a
 * failure's message its account and provenance differences, a file that
 * could not be read an error, a warning a pass with its account on
 * system-out. An HTML page for people: every case's thumbnail at a glance,
 * then each case that did not pass with golden, new and their difference,
 * a flip and a slider between golden and new, its figures and what its
 * provenance says changed. The page loads nothing but the pictures beside
 * it (a content security policy says so to the browser), so the folder
 * works offline and as a CI artifact. Both files are written all or
 * nothing. */
#include "core/internal.h"
#include "job/check.h"
#include "job/job_internal.h"
#include "files/safe_file.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

/* ------------------------------------------------------------ escaping */

/* s made printable (bb_text_printable: controls and bytes that are not
 * UTF-8 as \xNN, which XML 1.0 and HTML then hold) and escaped for markup,
 * appended to t. */
static void put_escaped(bb__text *t, const char *s) {
  const size_t cap = 4 * strlen(s) + 1;
  char *printable = malloc(cap);
  if (!printable) {
    t->failed = 1;
    return;
  }
  bb_text_printable(s, printable, cap);
  for (const char *p = printable; *p; p++) {
    switch (*p) {
    case '&':
      bb__text_add(t, "&amp;");
      break;
    case '<':
      bb__text_add(t, "&lt;");
      break;
    case '>':
      bb__text_add(t, "&gt;");
      break;
    case '"':
      bb__text_add(t, "&quot;");
      break;
    case '\'':
      bb__text_add(t, "&#39;");
      break;
    default:
      bb__text_append(t, p, 1);
    }
  }
  free(printable);
}

/* Text of several lines escaped line by line, the line breaks kept. */
static void put_lines(bb__text *t, const char *s) {
  for (const char *line = s; *line;) {
    const size_t n = strcspn(line, "\n");
    char *one = strndup(line, n);
    if (!one) {
      t->failed = 1;
      return;
    }
    put_escaped(t, one);
    free(one);
    line += n;
    if (*line == '\n') {
      bb__text_add(t, "\n");
      line++;
    }
  }
}

static bb_status write_text(const char *path, bb__text *t, bb_error *err) {
  if (t->failed) {
    bb__text_free(t);
    return bb__fail(err, BB_ERR_MEMORY, "%s: out of memory", path);
  }
  bb_status st = bb__file_write(path, t->data ? t->data : "", t->length, err);
  bb__text_free(t);
  return st;
}

/* --------------------------------------------------------------- JUnit */

static int is_error(bb_check_status s) {
  return s == BB_CHECK_UNREADABLE;
}

static int is_failure(bb_check_status s) {
  return s == BB_CHECK_FAILURE || s == BB_CHECK_DIFFERENT_SIZE || s == BB_CHECK_MISSING ||
         s == BB_CHECK_EXTRA;
}

bb_status bb__check_junit(const char *path, const char *suite,
                          bb__check_case *const *cases, int count, bb_error *err) {
  int failures = 0, errors = 0;
  double seconds = 0;
  for (int i = 0; i < count; i++) {
    failures += is_failure(cases[i]->pub.status);
    errors += is_error(cases[i]->pub.status);
    seconds += cases[i]->pub.seconds;
  }
  bb__text t = {0};
  bb__text_add(&t, "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n");
  bb__text_printf(&t,
                  "<testsuites name=\"bumpbake check\" tests=\"%d\" failures=\"%d\" "
                  "errors=\"%d\" skipped=\"0\" time=\"%.3f\">\n",
                  count, failures, errors, seconds);
  bb__text_add(&t, "<testsuite name=\"");
  put_escaped(&t, suite);
  bb__text_printf(&t,
                  "\" tests=\"%d\" failures=\"%d\" errors=\"%d\" skipped=\"0\" "
                  "time=\"%.3f\">\n",
                  count, failures, errors, seconds);
  for (int i = 0; i < count && !t.failed; i++) {
    const bb_check_case *k = &cases[i]->pub;
    bb__text_add(&t, "<testcase classname=\"bumpbake.check.");
    put_escaped(&t, k->kind[0] ? k->kind : "map");
    bb__text_add(&t, "\" name=\"");
    put_escaped(&t, k->name);
    bb__text_add(&t, "\" file=\"");
    put_escaped(&t, k->golden);
    bb__text_printf(&t, "\" time=\"%.6f\"", k->seconds);
    if (k->status == BB_CHECK_PASS && !k->update_error) {
      bb__text_add(&t, "/>\n");
      continue;
    }
    bb__text_add(&t, ">\n");
    char *text = bb__check_case_text(k);
    if (!text) {
      t.failed = 1;
      break;
    }
    const size_t first = strcspn(text, "\n");
    char *line = strndup(text, first);
    const char *element = is_error(k->status)     ? "error"
                          : is_failure(k->status) ? "failure"
                                                  : NULL;
    if (!line) {
      t.failed = 1;
    } else if (element) {
      bb__text_printf(&t, "<%s type=\"%s\" message=\"", element,
                      bb__check_status_name(k->status));
      put_escaped(&t, line);
      bb__text_add(&t, "\">");
      put_lines(&t, text);
      bb__text_printf(&t, "</%s>\n", element);
    } else { /* a warning passes; what it found goes with it */
      bb__text_printf(&t, "<system-out>%s: ", bb__check_status_name(k->status));
      put_lines(&t, text);
      bb__text_add(&t, "</system-out>\n");
    }
    if (k->updated)
      bb__text_add(&t, "<system-err>the golden was updated</system-err>\n");
    free(line);
    free(text);
    bb__text_add(&t, "</testcase>\n");
  }
  bb__text_add(&t, "</testsuite>\n</testsuites>\n");
  return write_text(path, &t, err);
}

/* ---------------------------------------------------------------- HTML */

static const char *status_class(bb_check_status s) {
  switch (s) {
  case BB_CHECK_PASS:
    return "pass";
  case BB_CHECK_WARNING:
    return "warn";
  case BB_CHECK_FAILURE:
    return "fail";
  case BB_CHECK_DIFFERENT_SIZE:
    return "size";
  case BB_CHECK_UNREADABLE:
    return "unreadable";
  case BB_CHECK_MISSING:
    return "missing";
  case BB_CHECK_EXTRA:
    return "extra";
  }
  return "fail";
}

/* The page's style and script: inline, as the policy allows nothing else. */
static const char PAGE_HEAD[] =
    "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">\n"
    "<meta http-equiv=\"Content-Security-Policy\" content=\"default-src 'none'; img-src "
    "'self'; style-src 'unsafe-inline'; script-src 'unsafe-inline'\">\n"
    "<meta name=\"viewport\" content=\"width=device-width\">\n"
    "<style>\n"
    "body{font:14px/1.4 system-ui,sans-serif;margin:0;background:#1d1f21;color:#ddd}\n"
    "header{padding:12px 20px;background:#26292c;position:sticky;top:0;z-index:2}\n"
    "h1{font-size:18px;margin:0 0 6px}h2{font-size:15px;margin:0 0 8px}\n"
    ".counts span{display:inline-block;margin-right:12px;padding:1px "
    "8px;border-radius:9px}\n"
    "main{padding:12px 20px}\n"
    ".grid{display:flex;flex-wrap:wrap;gap:6px;margin-bottom:24px}\n"
    ".thumb{width:64px;height:64px;border:3px solid;border-radius:3px;display:flex;"
    "align-items:center;justify-content:center;background:#202224;text-decoration:none}\n"
    ".thumb i{display:block;background-repeat:no-repeat}\n"
    ".pass{border-color:#3c8d40}.warn{border-color:#d6a419}.fail,.size,.missing,.extra"
    "{border-color:#d8412f}.unreadable{border-color:#9b59b6}\n"
    ".counts .pass{background:#3c8d40}.counts .warn{background:#b58a12}.counts .fail"
    "{background:#c0392b}.counts .unreadable{background:#8e44ad}\n"
    "section.case{border-left:6px solid;padding:10px 14px;margin:0 0 "
    "22px;background:#26292c}\n"
    ".views{display:flex;flex-wrap:wrap;gap:16px;margin:10px 0;align-items:flex-start}\n"
    "figure{margin:0}.view{width:min-content}\n"
    ".view figcaption{font-size:12px;color:#aaa;margin-top:3px}\n"
    ".frame{position:relative;overflow:hidden;background:#111}\n"
    ".frame img{position:absolute;top:0;image-rendering:pixelated;max-width:none}\n"
    ".over{position:absolute;inset:0;overflow:hidden}\n"
    ".split{position:absolute;top:0;bottom:0;width:1px;background:#fff;opacity:.8}\n"
    "table{border-collapse:collapse}td{padding:1px 10px 1px 0}\n"
    "pre{background:#17191b;padding:6px 8px;white-space:pre-wrap;margin:6px 0}\n"
    "button,label{font:inherit}.controls{margin:4px 0}\n"
    "</style>\n";

/* Switches the flip view between golden and new (a click, or a timer) and
 * moves the slider's clip; the parts of a strip are its img's offsets. */
static const char PAGE_SCRIPT[] =
    "<script>\n"
    "function part(img,i){img.style.left=(-i*img.dataset.w)+'px';}\n"
    "document.querySelectorAll('.flip').forEach(function(f){\n"
    "  var "
    "img=f.querySelector('img'),label=f.parentNode.querySelector('figcaption'),n=0;\n"
    "  function show(i){n=i;part(img,i);label.textContent=i?'flip: new':'flip: "
    "golden';}\n"
    "  f.addEventListener('click',function(){show(1-n);});\n"
    "  var box=f.parentNode.querySelector('input[type=checkbox]'),timer=null;\n"
    "  box.addEventListener('change',function(){clearInterval(timer);\n"
    "    if(box.checked)timer=setInterval(function(){show(1-n);},600);});\n"
    "});\n"
    "document.querySelectorAll('.slider').forEach(function(s){\n"
    "  var over=s.querySelector('.over'),split=s.querySelector('.split'),\n"
    "      range=s.parentNode.querySelector('input[type=range]');\n"
    "  function move(){over.style.clipPath='inset(0 0 0 '+range.value+'%)';\n"
    "    split.style.left=range.value+'%';}\n"
    "  range.addEventListener('input',move);move();\n"
    "});\n"
    "var only=document.getElementById('only');\n"
    "only.addEventListener('change',function(){document.querySelectorAll('.thumb.pass')"
    ".forEach(function(t){t.style.display=only.checked?'none':'';});});\n"
    "</script>\n";

/* A frame showing part `index` of the case's strip at scale s. */
static void put_frame(bb__text *t, const bb__check_case *k, int index, int scale,
                      const char *cls) {
  const int w = k->strip_width * scale, h = k->strip_height * scale;
  bb__text_printf(t, "<div class=\"frame %s\" style=\"width:%dpx;height:%dpx\">", cls, w,
                  h);
  bb__text_printf(t,
                  "<img src=\"%s\" alt=\"\" data-w=\"%d\" width=\"%d\" height=\"%d\" "
                  "style=\"left:%dpx\">",
                  k->strip, w, k->strip_width * k->strip_parts * scale, h, -index * w);
  bb__text_add(t, "</div>");
}

static void put_views(bb__text *t, const bb__check_case *k) {
  if (!k->strip)
    return;
  /* small maps are enlarged, texels kept square (pixelated), to be seen */
  const int side = k->strip_width > k->strip_height ? k->strip_width : k->strip_height;
  int scale = side > 0 ? 256 / side : 1;
  scale = scale < 1 ? 1 : scale > 8 ? 8 : scale;
  static const char *const names[3] = {"golden", "new", "difference"};
  bb__text_add(t, "<div class=\"views\">");
  for (int i = 0; i < k->strip_parts; i++) {
    bb__text_printf(t, "<figure class=\"view %s\">", names[i]);
    put_frame(t, k, i, scale, "");
    if (i == 2)
      bb__text_printf(t,
                      "<figcaption>difference: black none, white %.4g (square root "
                      "scale; a NaN against a number white too)</figcaption>",
                      k->heat_max);
    else
      bb__text_printf(t, "<figcaption>%s</figcaption>", names[i]);
    bb__text_add(t, "</figure>");
  }
  if (k->pub.width == k->pub.new_width && k->pub.height == k->pub.new_height) {
    bb__text_add(t, "<figure class=\"view\">");
    put_frame(t, k, 0, scale, "flip");
    bb__text_add(t, "<figcaption>flip: golden</figcaption><div class=\"controls\"><label>"
                    "<input type=\"checkbox\"> flip every 0.6 s</label> (or click)</div>"
                    "</figure>");
    const int w = k->strip_width * scale, h = k->strip_height * scale;
    bb__text_add(t, "<figure class=\"view\">");
    bb__text_printf(t, "<div class=\"frame slider\" style=\"width:%dpx;height:%dpx\">", w,
                    h);
    bb__text_printf(t,
                    "<img src=\"%s\" alt=\"\" data-w=\"%d\" width=\"%d\" height=\"%d\" "
                    "style=\"left:0\">",
                    k->strip, w, k->strip_width * k->strip_parts * scale, h);
    bb__text_printf(t,
                    "<div class=\"over\"><img src=\"%s\" alt=\"\" data-w=\"%d\" "
                    "width=\"%d\" height=\"%d\" style=\"left:%dpx\"></div>"
                    "<i class=\"split\"></i></div>",
                    k->strip, w, k->strip_width * k->strip_parts * scale, h, -w);
    bb__text_add(t, "<figcaption>slider: golden left, new right</figcaption>"
                    "<div class=\"controls\"><input type=\"range\" min=\"0\" max=\"100\" "
                    "value=\"50\" aria-label=\"slider\"></div></figure>");
  }
  bb__text_add(t, "</div>\n");
}

static void put_case(bb__text *t, const bb__check_case *k, int index) {
  const bb_check_case *p = &k->pub;
  bb__text_printf(t, "<section class=\"case %s\" id=\"case-%d\">",
                  status_class(p->status), index);
  bb__text_printf(t, "<h2>%s ", bb__check_status_name(p->status));
  put_escaped(t, p->name);
  if (p->kind[0]) {
    bb__text_add(t, " (");
    put_escaped(t, p->kind);
    bb__text_add(t, ")");
  }
  bb__text_add(t, "</h2>\n");
  char *text = bb__check_case_text(p);
  if (!text) {
    t->failed = 1;
    return;
  }
  bb__text_add(t, "<pre class=\"account\">");
  put_lines(t, text);
  bb__text_add(t, "</pre>\n<table>");
  bb__text_add(t, "<tr><td>golden</td><td>");
  put_escaped(t, p->golden);
  bb__text_add(t, "</td></tr><tr><td>new</td><td>");
  put_escaped(t, p->fresh ? p->fresh : "(none)");
  bb__text_add(t, "</td></tr>");
  if (p->status <= BB_CHECK_FAILURE)
    bb__text_printf(t,
                    "<tr><td>limits</td><td>-fail %g -failpercent %g -hardfail %g "
                    "-allowfailures %ld -warn %g -warnpercent %g -hardwarn %g</td></tr>",
                    p->limits.fail, p->limits.fail_percent, p->limits.hard_fail,
                    p->limits.allow_failures, p->limits.warn, p->limits.warn_percent,
                    p->limits.hard_warn);
  if (p->updated)
    bb__text_add(t, "<tr><td>update</td><td>the golden was written</td></tr>");
  bb__text_add(t, "</table>\n");
  free(text);
  put_views(t, k);
  bb__text_add(t, "</section>\n");
}

/* The thumbnail of case k: its cell of its atlas, linked to its section
 * when it has one. */
static void put_thumb(bb__text *t, const bb__check_case *k, int index) {
  const bb_check_case *p = &k->pub;
  if (p->status == BB_CHECK_PASS)
    bb__text_printf(t, "<span class=\"thumb %s\" title=\"", status_class(p->status));
  else
    bb__text_printf(t, "<a class=\"thumb %s\" href=\"#case-%d\" title=\"",
                    status_class(p->status), index);
  bb__text_printf(t, "%s ", bb__check_status_name(p->status));
  put_escaped(t, p->name);
  bb__text_add(t, "\">");
  if (k->thumbs)
    bb__text_printf(t,
                    "<i style=\"width:%dpx;height:%dpx;background-image:url(%s);"
                    "background-position:-%dpx -%dpx\"></i>",
                    k->thumb_width, k->thumb_height, k->thumbs,
                    k->thumb_cell % BB__CHECK_ATLAS_SIDE * BB__CHECK_THUMB,
                    k->thumb_cell / BB__CHECK_ATLAS_SIDE * BB__CHECK_THUMB);
  bb__text_add(t, p->status == BB_CHECK_PASS ? "</span>" : "</a>");
}

bb_status bb__check_html(const char *dir, const char *title, bb__check_case *const *cases,
                         int count, bb_error *err) {
  int counts[BB_CHECK_EXTRA + 1] = {0};
  for (int i = 0; i < count; i++)
    counts[cases[i]->pub.status]++;
  bb__text t = {0};
  bb__text_add(&t, PAGE_HEAD);
  bb__text_add(&t, "<title>bumpbake check ");
  put_escaped(&t, title);
  bb__text_add(&t, "</title></head><body>\n<header><h1>bumpbake check ");
  put_escaped(&t, title);
  bb__text_printf(&t, "</h1><div class=\"counts\"><span>%d maps</span>", count);
  static const char *const words[] = {
      "passed",     "warnings", "failed", "of another size",
      "unreadable", "missing",  "extra"};
  for (int s = 0; s <= BB_CHECK_EXTRA; s++)
    if (counts[s] || s == BB_CHECK_PASS)
      bb__text_printf(&t, "<span class=\"%s\">%d %s</span>",
                      status_class((bb_check_status)s), counts[s], words[s]);
  bb__text_add(&t, "<label><input type=\"checkbox\" id=\"only\"> hide passing</label>"
                   "</div></header>\n<main>\n<div class=\"grid\">");
  for (int i = 0; i < count && !t.failed; i++)
    put_thumb(&t, cases[i], i);
  bb__text_add(&t, "</div>\n");
  if (count - counts[BB_CHECK_PASS] == 0)
    bb__text_add(&t, "<p>Every map matches its golden.</p>\n");
  /* the cases that did not pass, worst first (a stable order by exit code) */
  for (int code = BB_COMPARE_CANNOT_READ; code >= 1; code--)
    for (int i = 0; i < count && !t.failed; i++)
      if (cases[i]->pub.exit_code == code)
        put_case(&t, cases[i], i);
  bb__text_add(&t, "</main>\n");
  bb__text_add(&t, PAGE_SCRIPT);
  bb__text_add(&t, "</body></html>\n");
  char path[4096];
  snprintf(path, sizeof path, "%s/index.html", dir);
  return write_text(path, &t, err);
}
