// saved_state_support.h — saved states rewritten for the saved-state tests:
// as an older format version wrote them (less the fields it lacked), or
// damaged on purpose, with a header that matches (so only the payload's
// checks can refuse them).
#pragma once

#include <cstring>
#include <functional>
#include <vector>

#include "runtime/state_format.h"
#include "sinew/saved_state.h"

namespace sinew::test {

/// `state`'s payload less its last `drop` bytes, changed by `edit` (given the
/// payload alone), with the header made again (size, hash) and `version`.
inline SavedState rewritten(const SavedState& state, std::size_t drop, std::uint32_t version = kSavedStateVersion,
                            const std::function<void(std::vector<std::byte>&)>& edit = {}) {
  std::vector<std::byte> payload(state.bytes.begin() + state_format::kHeaderBytes, state.bytes.end() - drop);
  if (edit) edit(payload);
  SavedState out;
  state_format::Writer w(out.bytes);
  w.begin();
  out.bytes.insert(out.bytes.end(), payload.begin(), payload.end());
  w.finish();
  std::memcpy(out.bytes.data() + 8, &version, 4);
  return out;
}

}  // namespace sinew::test
