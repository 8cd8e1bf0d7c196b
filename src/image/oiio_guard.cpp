// oiio_guard.cpp: what bb::guard (oiio_guard.h) makes of an exception.
#include "image/oiio_guard.h"
#include "core/internal.h"

#include <exception>
#include <new>
#include <stdexcept>

namespace bb {

bb_status exception_status(bb_error *err, const char *subject, const guard_words &w) noexcept {
  try {
    throw; // the exception being handled, classified once, here
  } catch (const std::bad_alloc &) {
    return bb__fail(err, BB_ERR_MEMORY, "%s: out of memory while %s", subject, w.doing);
  } catch (const std::length_error &) {
    // A size read from a file that no container can hold (a GIF of
    // 65535 x 65535 made OpenImageIO resize a vector past its maximum).
    return bb__fail(err, BB_ERR_SIZE, "%s: %sa size it declares is too large to allocate",
                    subject, w.reason_prefix);
  } catch (const std::exception &e) {
    try {
      return bb__fail(err, w.failure, "%s: %s%s", subject, w.reason_prefix,
                      one_line(e.what()).c_str());
    } catch (...) {
      return bb__fail(err, BB_ERR_MEMORY, "%s: out of memory while %s", subject, w.doing);
    }
  } catch (...) {
    return bb__fail(err, w.failure, "%s: %sunknown error while %s", subject, w.reason_prefix,
                    w.doing);
  }
}

std::string one_line(std::string s) {
  while (!s.empty() && (s.back() == '\n' || s.back() == '\r')) s.pop_back();
  std::string out;
  for (char c : s) {
    if (c == '\n')
      out += "; ";
    else if (c != '\r')
      out += c;
  }
  return out.empty() ? std::string("unknown OpenImageIO error") : out;
}

std::string first_line(const std::string &s) { return s.substr(0, s.find('\n')); }

} // namespace bb
