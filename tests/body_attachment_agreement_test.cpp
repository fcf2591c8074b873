// body_attachment_agreement_test.cpp — xpbd_solve_body_attachment on every
// GPU backend against the CPU reference (see agreement_support.h): random
// pairs of barycentric points (1 to 4 particles a side, unused slots
// repeating the side's first particle with weight 0), some particles or
// whole sides immovable, compliances 0 and not, break forces never, above
// and below the force the solve reaches, some already broken, first and
// later iterations, the measuring pass. The broken flags must agree
// bitwise: a break the CPU sees and a GPU misses would change the scene.
#include "agreement_support.h"

#include <cstdio>

#include "contact_params.h"

namespace sinew::test {
namespace {

using kernels::SolveParams;

TEST_P(Agreement, BodyAttachmentKernel) {
  const unsigned seed = std::random_device{}();
  SCOPED_TRACE("seed " + std::to_string(seed));
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> unit(0.0f, 1.0f), alpha(0.0f, 1e-4f), lam(-1e-2f, 1e-2f),
      force(1.0f, 4000.0f);
  const std::uint32_t first = 3, count = 300 + rng() % 50, total = first + count + 5;
  for (bool reset : {false, true}) {
    for (bool measure : {false, true}) {
      std::vector<float> x = random_particles(rng, 8 * total);
      std::vector<std::uint32_t> idx = one_colour(rng, total, 8);
      std::vector<float> data, lambda;
      std::uint32_t breakable = 0;
      for (std::uint32_t i = 0; i < total; ++i) {
        float w[8] = {};
        for (int side = 0; side < 2; ++side) {
          const std::uint32_t used = 1 + rng() % 4;
          float sum = 0.0f;
          for (std::uint32_t k = 0; k < used; ++k) sum += (w[4 * side + k] = unit(rng) + 0.01f);
          for (std::uint32_t k = 0; k < used; ++k) w[4 * side + k] /= sum;
          for (std::uint32_t k = used; k < 4; ++k) idx[8 * i + 4 * side + k] = idx[8 * i + 4 * side];
        }
        if (i % 13 == 5)  // a wholly immovable side
          for (int k = 0; k < 4; ++k) x[4 * idx[8 * i + k] + 3] = 0.0f;
        if (i % 29 == 7)  // both sides immovable
          for (int k = 0; k < 8; ++k) x[4 * idx[8 * i + k] + 3] = 0.0f;
        if (i % 17 == 3) {  // the two points on each other: single vertices at one place
          w[0] = w[4] = 1.0f;
          for (int k = 1; k < 4; ++k) w[k] = w[4 + k] = 0.0f, idx[8 * i + k] = idx[8 * i], idx[8 * i + 4 + k] = idx[8 * i + 4];
          for (int k = 0; k < 3; ++k) x[4 * idx[8 * i + 4] + k] = x[4 * idx[8 * i] + k];
        }
        // Break force: 0 (never) for a quarter, else random around the
        // forces |lambda| / h^2 the solve reaches (up to thousands here).
        const float brk = i % 4 == 0 ? 0.0f : force(rng);
        const float broken = i % 23 == 11 ? 1.0f : 0.0f;
        breakable += brk > 0.0f && broken == 0.0f;
        data.insert(data.end(), w, w + 8);
        data.insert(data.end(), {i % 3 == 0 ? 0.0f : alpha(rng), brk, broken, 0.0f});
        lambda.push_back(lam(rng));
      }
      KernelCase c{Kernel::xpbd_solve_body_attachment, count, {}, {}};
      c.bindings.push_back({x, false, 4});
      c.bindings.push_back({as_words(idx), false});
      c.bindings.push_back({data, false, 4});
      c.bindings.push_back({lambda, reset && !measure});
      c.bindings.push_back({std::vector<float>(total, 0.0f), measure});
      c.params = bytes_of(SolveParams{first, count, 3600.0f, reset ? 1u : 0u, 1.0f / 60.0f, 1.0f,
                                      measure ? 1u : 0u, 0});
      const std::string what = std::string("body attachment") + (reset ? " reset" : "") + (measure ? " measure" : "");
      const auto ref = run_on("cpu", c);
      const auto gpu = run_on(GetParam(), c);
      expect_agree(c, ref, gpu, what);
      report_difference(c, ref, gpu, GetParam() + " " + what);
      std::uint32_t broke = 0, flags_differ = 0;
      for (std::uint32_t i = first; i < first + count; ++i) {
        broke += ref[2][12 * i + 10] != data[12 * i + 10];
        flags_differ += ref[2][12 * i + 10] != gpu[2][12 * i + 10];
      }
      EXPECT_EQ(flags_differ, 0u) << what << ": broken flags differ";
      if (!measure) EXPECT_GT(broke, 0u) << what << ": no attachment broke; the case does not test breaking";
      if (!measure) EXPECT_LT(broke, breakable) << what << ": every breakable attachment broke";
      if (measure) EXPECT_EQ(broke, 0u) << what << ": the measuring pass broke an attachment";
      std::printf("[ agree    ] %s on %s: %u of %u breakable attachments broke, flags equal\n", what.c_str(),
                  GetParam().c_str(), broke, breakable);
    }
  }
}

}  // namespace
}  // namespace sinew::test
