// UTF-8 as RFC 3629 defines it, the one check of it in the project: the model file's class names
// must be UTF-8 (FORMAT.md, checked by the reader), and the offline toolchain's JSON summaries
// must be (RFC 8259, section 8.1) although the paths and ids they carry are any bytes but NUL.
// Header-only and standard library only, so that the predictor's model reader and the offline
// core can both include it.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string_view>

namespace dressguard::model {

// The length (1 to 4 bytes) of the well-formed UTF-8 sequence that begins at s[i], or 0 when none
// begins there: a continuation byte without its lead, a byte that leads nothing (0xF8-0xFF), a
// sequence cut short or broken by a byte that does not continue it, an overlong form (a shorter
// sequence says the same), a surrogate (U+D800-U+DFFF) or a code point past U+10FFFF.
// Needs i < s.size().
inline std::size_t utf8_sequence_at(std::string_view s, std::size_t i) {
  const auto c = static_cast<unsigned char>(s[i]);
  if (c < 0x80) return 1;
  if (c < 0xC0 || c > 0xF7) return 0;
  const std::size_t len = c >= 0xF0 ? 4 : c >= 0xE0 ? 3 : 2;
  const std::uint32_t least = len == 4 ? 0x10000 : len == 3 ? 0x800 : 0x80;  // below it: overlong
  std::uint32_t cp = c & (0x7Fu >> len);
  if (len > s.size() - i) return 0;
  for (std::size_t k = 1; k < len; ++k) {
    const auto t = static_cast<unsigned char>(s[i + k]);
    if ((t & 0xC0u) != 0x80u) return 0;
    cp = (cp << 6) | (t & 0x3Fu);
  }
  if (cp < least || cp > 0x10FFFF || (cp >= 0xD800 && cp <= 0xDFFF)) return 0;
  return len;
}

// Where `s` stops being well-formed UTF-8: the offset of the first byte that begins no
// well-formed sequence (utf8_sequence_at), or npos when all of it is.
inline std::size_t invalid_utf8_at(std::string_view s) {
  for (std::size_t i = 0; i < s.size();) {
    const std::size_t len = utf8_sequence_at(s, i);
    if (len == 0) return i;
    i += len;
  }
  return std::string_view::npos;
}

}  // namespace dressguard::model
