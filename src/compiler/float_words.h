// float_words.h — device buffers of mixed structs (the collider buffer: a
// header, then entries) are built and edited on the host as vectors of
// 4-byte words. These copy a trivially copyable struct in and out of such a
// vector by bytes (memcpy), never through a cast pointer.
#pragma once

#include <cstddef>
#include <cstring>
#include <type_traits>
#include <vector>

namespace sinew {

/// [in,out] out: grows by sizeof(T) / 4 words holding `value`.
template <class T>
void append_words(std::vector<float>& out, const T& value) {
  static_assert(std::is_trivially_copyable_v<T> && sizeof(T) % sizeof(float) == 0);
  const std::size_t at = out.size();
  out.resize(at + sizeof(T) / sizeof(float));
  std::memcpy(out.data() + at, &value, sizeof(T));
}

/// The T stored at word `at`. [pre] at + sizeof(T) / 4 <= words.size()
template <class T>
T load_words(const std::vector<float>& words, std::size_t at) {
  static_assert(std::is_trivially_copyable_v<T> && sizeof(T) % sizeof(float) == 0);
  T t;
  std::memcpy(&t, words.data() + at, sizeof(T));
  return t;
}

/// Overwrites the T at word `at`. [pre] at + sizeof(T) / 4 <= words.size()
template <class T>
void store_words(std::vector<float>& words, std::size_t at, const T& t) {
  static_assert(std::is_trivially_copyable_v<T> && sizeof(T) % sizeof(float) == 0);
  std::memcpy(words.data() + at, &t, sizeof(T));
}

}  // namespace sinew
