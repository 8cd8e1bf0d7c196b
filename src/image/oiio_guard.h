// oiio_guard.h: the one exception guard of the OpenImageIO C++ files
// (oiio_*.cpp), the only files that call OpenImageIO.
//
// OpenImageIO and the C++ runtime may throw (std::bad_alloc, a length_error
// from a header's absurd size, whatever a codec throws). No exception may
// cross into C: every extern "C" function of these files runs its body
// through bb::guard, which turns any exception into a bb_status and a
// one-line message naming the file, and nothing else in them catches.
// (As Embree's RTC_CATCH_BEGIN / RTC_CATCH_END: one catch site, one
// classification, bb::exception_status.)
#ifndef BB_IMAGE_OIIO_GUARD_H
#define BB_IMAGE_OIIO_GUARD_H

#include "bumpbake.h"

#include <string>

namespace bb {

// What a job calls its failures: the status of a failure the exception
// describes, the words put before its reason ("cannot write: "), and what
// the job was doing ("reading"), for "PATH: out of memory while reading".
struct guard_words {
  bb_status failure;
  const char *reason_prefix;
  const char *doing;
};

constexpr guard_words READING{BB_ERR_FORMAT, "", "reading"};
constexpr guard_words WRITING{BB_ERR_IO, "cannot write: ", "writing"};
constexpr guard_words DRAWING{BB_ERR_FORMAT, "", "drawing text"};
constexpr guard_words RESIZING{BB_ERR_ARGUMENT, "", "resizing"};

// The status of the exception being handled; call it only inside a catch
// block. subject names the file (or the job) in the message.
bb_status exception_status(bb_error *err, const char *subject, const guard_words &words) noexcept;

// Runs fn (returning bb_status); any exception becomes exception_status.
template <typename Fn>
bb_status guard(bb_error *err, const char *subject, const guard_words &words, Fn &&fn) noexcept {
  try {
    return fn();
  } catch (...) {
    return exception_status(err, subject, words);
  }
}

// Runs fn (returning T) for a query with no error to report: any exception
// gives fallback.
template <typename T, typename Fn> T guard_value(T fallback, Fn &&fn) noexcept {
  T value = fallback;
  bb_error ignored;
  guard(&ignored, "", READING, [&] {
    value = fn();
    return BB_OK;
  });
  return value;
}

// OpenImageIO's messages may hold several lines; a bb_error holds one.
std::string one_line(std::string s);

// The first line of a message.
std::string first_line(const std::string &s);

} // namespace bb

#endif // BB_IMAGE_OIIO_GUARD_H
