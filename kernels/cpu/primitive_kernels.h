// primitive_kernels.h — CPU reference kernels of the device primitives
// (kernels/shared/primitive_params.h): indirect arguments, exclusive scan,
// compaction, radix sort and reductions. Cooperative kernels (scan_blocks,
// scan_add, radix_histogram, radix_scatter, reduce_blocks) are called with a
// range of *groups* [begin, end) and do each group's work in order, item by
// item, exactly as the group's items would in lockstep; the others with a
// range of items.
#pragma once

#include <cstddef>
#include <cstdint>

namespace sinew::kernels {

void indirect_args(const void* params, std::byte* const* bindings, std::uint32_t begin, std::uint32_t end);
void scan_blocks(const void* params, std::byte* const* bindings, std::uint32_t begin, std::uint32_t end);
void scan_add(const void* params, std::byte* const* bindings, std::uint32_t begin, std::uint32_t end);
void compact_scatter(const void* params, std::byte* const* bindings, std::uint32_t begin, std::uint32_t end);
void radix_histogram(const void* params, std::byte* const* bindings, std::uint32_t begin, std::uint32_t end);
void radix_scatter(const void* params, std::byte* const* bindings, std::uint32_t begin, std::uint32_t end);
void reduce_blocks(const void* params, std::byte* const* bindings, std::uint32_t begin, std::uint32_t end);

}  // namespace sinew::kernels
