/* png_messages.h: libpng's own error line kept off stderr (png_messages.c). */
#ifndef BB_IO_PNG_MESSAGES_H
#define BB_IO_PNG_MESSAGES_H

#ifdef __cplusplus
extern "C" {
#endif

/* 1 once a libpng error handler has been wrapped. Every image read calls
 * it, which is what links png_messages.c into a static program. */
int bb__png_messages_wrapped(void);

#ifdef __cplusplus
}
#endif

#endif /* BB_IO_PNG_MESSAGES_H */
