// state_format.cpp — the SavedState header, its checks, and the file I/O.
#include "runtime/state_format.h"

#include <fstream>
#include <iterator>

namespace sinew {
namespace state_format {
namespace {

// FNV-1a, 64 bits: catches a damaged payload (not an attacker; nothing here needs more).
std::uint64_t hash(std::span<const std::byte> bytes) {
  std::uint64_t h = 14695981039346656037ull;
  for (std::byte b : bytes) h = (h ^ std::to_integer<std::uint64_t>(b)) * 1099511628211ull;
  return h;
}

struct Header {
  char magic[8];
  std::uint32_t version, byte_order;
  std::uint64_t payload_bytes, payload_hash;
};

Header read_header(std::span<const std::byte> bytes) {
  Header h{};
  std::memcpy(h.magic, bytes.data(), 8);
  std::memcpy(&h.version, bytes.data() + 8, 4);
  std::memcpy(&h.byte_order, bytes.data() + 12, 4);
  std::memcpy(&h.payload_bytes, bytes.data() + 16, 8);
  std::memcpy(&h.payload_hash, bytes.data() + 24, 8);
  return h;
}

Error bad(const std::string& what, const std::string& why) {
  return Error(ErrorCode::bad_input_file, what + ": not a sinew saved state: " + why);
}

}  // namespace

void Writer::finish() {
  const std::span<const std::byte> payload(out_.data() + kHeaderBytes, out_.size() - kHeaderBytes);
  const std::uint32_t version = kSavedStateVersion, order = kByteOrder;
  const std::uint64_t size = payload.size(), h = hash(payload);
  std::memcpy(out_.data(), kMagic, 8);
  std::memcpy(out_.data() + 8, &version, 4);
  std::memcpy(out_.data() + 12, &order, 4);
  std::memcpy(out_.data() + 16, &size, 8);
  std::memcpy(out_.data() + 24, &h, 8);
}

Status Reader::array_into(void* into, std::size_t expected, const char* name) {
  std::uint64_t n = 0;
  if (Status s = value(n); !s) return s;
  if (n != expected) return mismatch(name, n, expected);
  if (left_.size() < n) return truncated();
  if (n) std::memcpy(into, left_.data(), n);
  left_ = left_.subspan(n);
  return {};
}

Status Reader::truncated() const {
  return Error(ErrorCode::bad_input_file, what_ + ": the saved state ends early (its payload is truncated)");
}

Status Reader::mismatch(const char* name, std::uint64_t got, std::uint64_t want) const {
  return Error(ErrorCode::bad_parameter, what_ + ": the saved state is of another scene: its " + name + " holds " +
                                             std::to_string(got) + " (this scene: " + std::to_string(want) + ")");
}

Status open(std::span<const std::byte> bytes, const std::string& what, std::span<const std::byte>& payload,
            std::uint32_t* version) {
  if (bytes.size() < kHeaderBytes)
    return bad(what, std::to_string(bytes.size()) + " bytes, shorter than the " + std::to_string(kHeaderBytes) +
                         "-byte header");
  const Header h = read_header(bytes);
  if (std::memcmp(h.magic, kMagic, 8) != 0) return bad(what, "the magic is not \"sinewst\\x1a\"");
  if (h.byte_order != kByteOrder) return bad(what, "written on a machine of another byte order");
  if (h.version == 0 || h.version > kSavedStateVersion)
    return bad(what, "format version " + std::to_string(h.version) + "; this sinew reads versions 1 to " +
                         std::to_string(kSavedStateVersion));
  if (h.payload_bytes != bytes.size() - kHeaderBytes)
    return bad(what, "the header says " + std::to_string(h.payload_bytes) + " payload bytes, there are " +
                         std::to_string(bytes.size() - kHeaderBytes) + " (truncated or extended)");
  payload = bytes.subspan(kHeaderBytes);
  if (hash(payload) != h.payload_hash) return bad(what, "the payload's hash does not match (the state is damaged)");
  if (version) *version = h.version;
  return {};
}

}  // namespace state_format

std::uint64_t SavedState::frame() const {
  std::span<const std::byte> payload;
  if (!state_format::open(bytes, "frame", payload)) return 0;
  std::uint64_t frame = 0;
  state_format::Reader reader(payload, "frame");
  return reader.value(frame) ? frame : 0;
}

Status SavedState::write_file(const std::string& path) const {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  if (!out) return Error(ErrorCode::bad_input_file, "write_file: cannot open " + path + " for writing");
  out.write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
  out.close();
  if (!out) return Error(ErrorCode::bad_input_file, "write_file: writing " + path + " failed (disk full?)");
  return {};
}

Result<SavedState> SavedState::read_file(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return Error(ErrorCode::bad_input_file, "read_file: cannot open " + path);
  in.seekg(0, std::ios::end);
  const std::streamoff size = in.tellg();
  if (size < 0) return Error(ErrorCode::bad_input_file, "read_file: cannot read " + path);
  in.seekg(0, std::ios::beg);
  SavedState state;
  state.bytes.resize(static_cast<std::size_t>(size));
  in.read(reinterpret_cast<char*>(state.bytes.data()), size);
  if (!in) return Error(ErrorCode::bad_input_file, "read_file: cannot read " + path);
  std::span<const std::byte> payload;
  if (Status s = state_format::open(state.bytes, path, payload); !s) return s.error();
  return state;
}

}  // namespace sinew
