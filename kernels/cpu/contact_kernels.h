// contact_kernels.h — CPU reference kernels of attachments and contacts. (Stage in progress: the kernels are stubs until it lands.)
#pragma once

#include <cstddef>
#include <cstdint>

namespace sinew::kernels {

void xpbd_solve_attachment(const void* params, std::byte* const* bindings, std::uint32_t begin, std::uint32_t end);
void xpbd_solve_contacts(const void* params, std::byte* const* bindings, std::uint32_t begin, std::uint32_t end);

}  // namespace sinew::kernels
