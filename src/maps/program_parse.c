/* program_parse.c: DOOM 3 image-program text to a tree (program_internal.h).
 *
 * Grammar, as id Tech 4's R_ParseImageProgram_r reads it:
 *   program := expr END
 *   expr    := FUNCTION '(' arguments ')' | '_flat' | NAME
 * where each function fixes its arguments (heightmap: expr ',' number;
 * addnormals, add: expr ',' expr; scale: expr and four numbers; the others:
 * expr). Tokens are '(', ')', ',', "quoted names" and names: runs of any
 * other characters up to white space, so paths such as
 * textures/base_wall/a_h.tga need no quotes. Function names are matched
 * case-insensitively, like id's token.Icmp. */

#include "core/internal.h"
#include "maps/program_internal.h"
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

/* ----------------------------------------------------------------- tokens */

typedef enum tok_kind {
  TOK_END,
  TOK_OPEN,
  TOK_CLOSE,
  TOK_COMMA,
  TOK_NAME,
  TOK_QUOTED
} tok_kind;

typedef struct token {
  tok_kind kind;
  const char *start; /* the text (inside the quotes for TOK_QUOTED) */
  size_t length;
  int column; /* 1-based */
} token;

typedef struct parser {
  const char *text;
  const char *p; /* next character to read */
  token tok;     /* the current token */
  bb_error *err;
  bb_status status; /* first error, BB_OK while none */
} parser;

static int is_space(char c) {
  return c == ' ' || c == '\t' || c == '\n' || c == '\r';
}

static int ends_name(char c) {
  return c == '\0' || is_space(c) || c == '(' || c == ')' || c == ',' || c == '"';
}

static void fail_at(parser *ps, int column, const char *fmt, const char *detail) {
  if (ps->status != BB_OK)
    return;
  char what[320];
  snprintf(what, sizeof what, fmt, detail);
  ps->status =
      bb__fail(ps->err, BB_ERR_ARGUMENT, "syntax error at column %d: %s", column, what);
}

/* Reads the next token into ps->tok. */
static void advance(parser *ps) {
  while (is_space(*ps->p))
    ps->p++;
  token *t = &ps->tok;
  t->column = (int)(ps->p - ps->text) + 1;
  t->start = ps->p;
  t->length = 1;
  switch (*ps->p) {
  case '\0':
    t->kind = TOK_END;
    t->length = 0;
    return;
  case '(':
    t->kind = TOK_OPEN;
    ps->p++;
    return;
  case ')':
    t->kind = TOK_CLOSE;
    ps->p++;
    return;
  case ',':
    t->kind = TOK_COMMA;
    ps->p++;
    return;
  case '"': {
    const char *close = strchr(ps->p + 1, '"');
    if (!close) {
      fail_at(ps, t->column, "%s", "unterminated \"quoted name\"");
      t->kind = TOK_END;
      return;
    }
    t->kind = TOK_QUOTED;
    t->start = ps->p + 1;
    t->length = (size_t)(close - t->start);
    ps->p = close + 1;
    return;
  }
  default:
    break;
  }
  t->kind = TOK_NAME;
  while (!ends_name(*ps->p))
    ps->p++;
  t->length = (size_t)(ps->p - t->start);
}

/* The current token as text for messages ("end of program" at the end). */
static const char *token_text(const token *t, char *buf, size_t cap) {
  if (t->kind == TOK_END)
    snprintf(buf, cap, "the end of the program");
  else if (t->kind == TOK_QUOTED)
    snprintf(buf, cap, "\"%.*s\"", (int)(t->length < 64 ? t->length : 64), t->start);
  else
    snprintf(buf, cap, "'%.*s'", (int)(t->length < 64 ? t->length : 64), t->start);
  return buf;
}

/* Consumes a token of kind, else fails with "expected WHAT, found ...". */
static void expect(parser *ps, tok_kind kind, const char *what) {
  if (ps->status != BB_OK)
    return;
  if (ps->tok.kind != kind) {
    char found[96], msg[256];
    snprintf(msg, sizeof msg, "expected %s, found %s", what,
             token_text(&ps->tok, found, sizeof found));
    fail_at(ps, ps->tok.column, "%s", msg);
    return;
  }
  advance(ps);
}

/* ------------------------------------------------------------- functions */

typedef struct function {
  const char *name;
  prog_op op;
  int images;  /* image operands */
  int numbers; /* numeric operands after them */
} function;

static const function FUNCTIONS[] = {
    {"heightmap", PROG_HEIGHTMAP, 1, 1},
    {"addnormals", PROG_ADDNORMALS, 2, 0},
    {"smoothnormals", PROG_SMOOTHNORMALS, 1, 0},
    {"add", PROG_ADD, 2, 0},
    {"scale", PROG_SCALE, 1, 4},
    {"invertAlpha", PROG_INVERT_ALPHA, 1, 0},
    {"invertColor", PROG_INVERT_COLOR, 1, 0},
    {"makeIntensity", PROG_MAKE_INTENSITY, 1, 0},
    {"makeAlpha", PROG_MAKE_ALPHA, 1, 0},
};
#define FUNCTION_COUNT ((int)(sizeof FUNCTIONS / sizeof FUNCTIONS[0]))

const char *bb__program_op_name(prog_op op) {
  if (op == PROG_IMAGE)
    return "image";
  if (op == PROG_FLAT)
    return "_flat";
  for (int i = 0; i < FUNCTION_COUNT; i++)
    if (FUNCTIONS[i].op == op)
      return FUNCTIONS[i].name;
  return "unknown";
}

static const function *find_function(const token *t) {
  for (int i = 0; i < FUNCTION_COUNT; i++)
    if (strlen(FUNCTIONS[i].name) == t->length &&
        strncasecmp(FUNCTIONS[i].name, t->start, t->length) == 0)
      return &FUNCTIONS[i];
  return NULL;
}

static void fail_unknown_function(parser *ps, const token *t) {
  if (ps->status != BB_OK)
    return;
  char known[256] = "";
  for (int i = 0; i < FUNCTION_COUNT; i++) {
    strcat(known, FUNCTIONS[i].name);
    strcat(known, i + 1 < FUNCTION_COUNT ? ", " : "");
  }
  ps->status =
      bb__fail(ps->err, BB_ERR_ARGUMENT,
               "unknown function '%.*s' at column %d (known: %s, and the image "
               "_flat)",
               (int)(t->length < 64 ? t->length : 64), t->start, t->column, known);
}

/* --------------------------------------------------------------- the tree */

static void free_node(prog_node *n) {
  if (!n)
    return;
  free_node(n->args[0]);
  free_node(n->args[1]);
  free(n->name);
  free(n);
}

static prog_node *new_node(parser *ps, prog_op op, int column) {
  prog_node *n = calloc(1, sizeof *n);
  if (!n && ps->status == BB_OK)
    ps->status = bb__fail(ps->err, BB_ERR_MEMORY, "out of memory parsing the program");
  if (n) {
    n->op = op;
    n->column = column;
  }
  return n;
}

/* A number operand: the whole token must be a finite number. */
static double parse_number(parser *ps, const char *function_name) {
  if (ps->status != BB_OK)
    return 0.0;
  const token t = ps->tok;
  char buf[64], found[96], msg[192];
  if (t.kind == TOK_NAME && t.length < sizeof buf) {
    memcpy(buf, t.start, t.length);
    buf[t.length] = '\0';
    char *end = NULL;
    errno = 0;
    double v = strtod(buf, &end);
    if (end != buf && *end == '\0' && errno != ERANGE && isfinite(v)) {
      advance(ps);
      return v;
    }
  }
  snprintf(msg, sizeof msg, "%s needs a number here, found %s", function_name,
           token_text(&t, found, sizeof found));
  fail_at(ps, t.column, "%s", msg);
  return 0.0;
}

static prog_node *parse_expr(parser *ps, int depth);

/* FUNCTION '(' operands ')', the name already read as the current token. */
static prog_node *parse_call(parser *ps, const function *f, int column, int depth) {
  prog_node *n = new_node(ps, f->op, column);
  if (!n)
    return NULL;
  char what[64];
  snprintf(what, sizeof what, "'(' after %s", f->name);
  expect(ps, TOK_OPEN, what);
  for (int i = 0; i < f->images && ps->status == BB_OK; i++) {
    if (i > 0)
      expect(ps, TOK_COMMA, "',' between the images");
    n->args[i] = parse_expr(ps, depth + 1);
  }
  for (int i = 0; i < f->numbers && ps->status == BB_OK; i++) {
    snprintf(what, sizeof what, "',' and the %s of %s",
             f->op == PROG_HEIGHTMAP ? "scale" : (i == 0 ? "4 factors" : "next factor"),
             f->name);
    expect(ps, TOK_COMMA, what);
    n->numbers[i] = parse_number(ps, f->name);
  }
  snprintf(what, sizeof what, "')' closing %s", f->name);
  expect(ps, TOK_CLOSE, what);
  return n;
}

/* An image name: a path, or _flat. */
static prog_node *parse_image(parser *ps, const token *t) {
  int is_flat =
      t->kind == TOK_NAME && t->length == 5 && strncasecmp(t->start, "_flat", 5) == 0;
  prog_node *n = new_node(ps, is_flat ? PROG_FLAT : PROG_IMAGE, t->column);
  if (!n || is_flat)
    return n;
  if (t->length == 0) {
    fail_at(ps, t->column, "%s", "empty image name \"\"");
    return n;
  }
  n->name = malloc(t->length + 1);
  if (!n->name) {
    if (ps->status == BB_OK)
      ps->status = bb__fail(ps->err, BB_ERR_MEMORY, "out of memory parsing the program");
    return n;
  }
  memcpy(n->name, t->start, t->length);
  n->name[t->length] = '\0';
  return n;
}

static prog_node *parse_expr(parser *ps, int depth) {
  if (ps->status != BB_OK)
    return NULL;
  const token t = ps->tok;
  if (depth > BB__PROGRAM_MAX_DEPTH) {
    fail_at(ps, t.column, "programs nest at most %s calls deep", "64");
    return NULL;
  }
  if (t.kind != TOK_NAME && t.kind != TOK_QUOTED) {
    char found[96], msg[256];
    snprintf(msg, sizeof msg, "expected an image or a function, found %s",
             token_text(&t, found, sizeof found));
    fail_at(ps, t.column, "%s", msg);
    return NULL;
  }
  advance(ps);
  const function *f = t.kind == TOK_NAME ? find_function(&t) : NULL;
  if (f)
    return parse_call(ps, f, t.column, depth);
  if (t.kind == TOK_NAME && ps->tok.kind == TOK_OPEN) {
    fail_unknown_function(ps, &t);
    return NULL;
  }
  return parse_image(ps, &t);
}

bb_status bb__program_parse(const char *text, bb__program **out, bb_error *err) {
  if (!out)
    return bb__fail(err, BB_ERR_ARGUMENT, "program parse: out is NULL");
  *out = NULL;
  if (!text)
    return bb__fail(err, BB_ERR_ARGUMENT, "program parse: text is NULL");
  parser ps = {text, text, {TOK_END, text, 0, 1}, err, BB_OK};
  advance(&ps);
  if (ps.status == BB_OK && ps.tok.kind == TOK_END)
    return bb__fail(err, BB_ERR_ARGUMENT, "syntax error at column 1: empty program");
  prog_node *root = parse_expr(&ps, 0);
  if (ps.status == BB_OK && ps.tok.kind != TOK_END) {
    char found[96], msg[256];
    snprintf(msg, sizeof msg, "unexpected %s after the end of the program",
             token_text(&ps.tok, found, sizeof found));
    fail_at(&ps, ps.tok.column, "%s", msg);
  }
  if (ps.status != BB_OK) {
    free_node(root);
    return ps.status;
  }
  bb__program *p = malloc(sizeof *p);
  if (!p) {
    free_node(root);
    return bb__fail(err, BB_ERR_MEMORY, "out of memory parsing the program");
  }
  p->root = root;
  *out = p;
  return BB_OK;
}

static size_t collect_images(const prog_node *n, const char **names, size_t cap,
                             size_t count) {
  if (!n)
    return count;
  if (n->op == PROG_IMAGE) {
    if (count < cap)
      names[count] = n->name;
    return count + 1;
  }
  count = collect_images(n->args[0], names, cap, count);
  return collect_images(n->args[1], names, cap, count);
}

size_t bb__program_images(const bb__program *program, const char **names, size_t cap) {
  if (!program)
    return 0;
  return collect_images(program->root, names, names ? cap : 0, 0);
}

void bb__program_free(bb__program *program) {
  if (!program)
    return;
  free_node(program->root);
  free(program);
}
