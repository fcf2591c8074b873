// contact_agreement_test.cpp — the contact kernels on every GPU backend against the
// CPU reference, kernel by kernel (see agreement_support.h).
#include "agreement_support.h"
