/* serve_page.c: the page `bumpbake serve` serves, its files (share/serve/
 * and shaders/ssbump_relief.glsl, the very shader functions `render
 * --relief` evaluates on the CPU) embedded in the binary when it is built,
 * so the page needs no file at run time, no network and no CDN. The
 * Makefile rebuilds this file when one of them changes. */
#include "serve.h"

#include <string.h>

#define EMBED(symbol, path)                                                              \
  __asm__(".section .rodata\n"                                                           \
          ".global " #symbol "\n"                                                        \
          ".type " #symbol ", @object\n"                                                 \
          ".balign 16\n" #symbol ":\n"                                                   \
          ".incbin \"" path "\"\n"                                                       \
          ".global " #symbol "_end\n" #symbol "_end:\n"                                  \
          ".byte 0\n"                                                                    \
          ".previous\n");                                                                \
  extern const unsigned char symbol[], symbol##_end[]

EMBED(serve_index_html, "share/serve/index.html");
EMBED(serve_js, "share/serve/serve.js");
EMBED(serve_css, "share/serve/serve.css");
EMBED(serve_frag_glsl, "share/serve/serve.frag.glsl");
EMBED(serve_relief_glsl, "shaders/ssbump_relief.glsl");

static serve_asset assets[5];

static void init_assets(void) {
  {
    assets[0] = (serve_asset){"index.html", "text/html; charset=utf-8", serve_index_html,
                              (size_t)(serve_index_html_end - serve_index_html)};
    assets[1] = (serve_asset){"serve.js", "text/javascript; charset=utf-8", serve_js,
                              (size_t)(serve_js_end - serve_js)};
    assets[2] =
        (serve_asset){"serve.frag.glsl", "text/plain; charset=utf-8", serve_frag_glsl,
                      (size_t)(serve_frag_glsl_end - serve_frag_glsl)};
    assets[3] = (serve_asset){"ssbump_relief.glsl", "text/plain; charset=utf-8",
                              serve_relief_glsl,
                              (size_t)(serve_relief_glsl_end - serve_relief_glsl)};
    assets[4] = (serve_asset){"serve.css", "text/css; charset=utf-8", serve_css,
                              (size_t)(serve_css_end - serve_css)};
  }
}

const serve_asset *serve_asset_find(const char *name) {
  static pthread_once_t once = PTHREAD_ONCE_INIT;
  pthread_once(&once, init_assets);
  for (size_t i = 0; i < sizeof assets / sizeof assets[0]; i++)
    if (!strcmp(assets[i].name, name))
      return &assets[i];
  return NULL;
}
