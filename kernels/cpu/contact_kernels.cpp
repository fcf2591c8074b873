// contact_kernels.cpp — CPU reference kernels of attachments and contacts. (Stage in progress.)
#include "cpu/contact_kernels.h"

namespace sinew::kernels {

void xpbd_solve_attachment(const void*, std::byte* const*, std::uint32_t, std::uint32_t) {}
void xpbd_solve_contacts(const void*, std::byte* const*, std::uint32_t, std::uint32_t) {}

}  // namespace sinew::kernels
