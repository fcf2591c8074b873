// contact_coloring_test.cpp — the contacts' colouring on the device
// (coloring/device_contact_coloring.h, Jones and Plassmann 1993 with hashed
// priorities, a cap and an overflow set) and its sequential reference
// (coloring/jones_plassmann.h). The reference is checked against the
// definition, contact by contact: a contact's colour is the lowest that no
// neighbour of higher priority holds, a contact is in the overflow set only
// when its neighbours of higher priority hold every colour below the cap
// (or the rounds ran out first), no two contacts of one colour share a
// movable particle. The device's colouring equals the reference contact
// for contact on every backend, and the backends' table and order are the
// same words: on random sets and on the real self-contacts of the bent
// kidney_57k surface.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <numeric>
#include <optional>
#include <string>
#include <vector>

#include "coloring/device_contact_coloring.h"
#include "coloring/jones_plassmann.h"
#include "program/xpbd_program.h"
#include "contact_coloring_params.h"
#include "contact_coloring_support.h"
#include "test_support.h"

namespace sinew::test {
namespace {

std::uint32_t priority(std::uint32_t c) { return kernels::contact_color_priority(c); }

// The definition, by brute force over each contact's neighbours (the
// contacts that share a movable particle with it): what the reference must be.
void expect_greedy_in_priority_order(const ContactSet& s, const CappedColoring& got, std::uint32_t colors) {
  const std::uint32_t n = s.contacts();
  // Neighbours through a particle index (contacts per particle).
  std::vector<std::vector<std::uint32_t>> at(s.movable.size());
  for (std::uint32_t c = 0; c < n; ++c)
    for (int k = 0; k < 4; ++k) {
      auto& list = at[s.particles[4 * std::size_t{c} + k]];
      if (list.empty() || list.back() != c) list.push_back(c);
    }
  std::uint32_t out_of_rounds = 0;
  for (std::uint32_t c = 0; c < n; ++c) {
    std::vector<bool> held(colors + 1, false);
    for (int k = 0; k < 4; ++k) {
      const std::uint32_t p = s.particles[4 * std::size_t{c} + k];
      if (!s.movable[p]) continue;
      for (std::uint32_t d : at[p])
        if (d != c && priority(d) > priority(c)) held[got.color_of[d]] = true;
    }
    const std::uint32_t k = got.color_of[c];
    ASSERT_LE(k, colors);
    std::uint32_t lowest = 0;
    while (lowest < colors && held[lowest]) ++lowest;
    if (k == colors && lowest < colors) {
      ++out_of_rounds;  // a free colour: only the rounds can have run out
      continue;
    }
    ASSERT_EQ(k, lowest) << "contact " << c << ": not the lowest colour its neighbours of higher priority leave";
  }
  EXPECT_EQ(out_of_rounds, got.out_of_rounds);
}

// A random contact set to colour, with the cap and the rounds.
struct RandomCase {
  std::uint32_t contacts, particles;
  double pinned;
  std::uint32_t colors, rounds;
  [[nodiscard]] std::string name() const {
    return std::to_string(contacts) + " contacts, cap " + std::to_string(colors) + ", rounds " + std::to_string(rounds);
  }
};

TEST(JonesPlassmann, IsTheGreedyColouringInDescendingPriorityWithinTheCap) {
  for (const RandomCase& k : {RandomCase{2000, 3000, 0.1, 128, 254}, RandomCase{3000, 600, 0.2, 8, 254},
                              RandomCase{500, 40, 0.0, 4, 254}, RandomCase{2000, 300, 0.3, 32, 3},
                              RandomCase{1, 4, 0.0, 1, 1}}) {
    SCOPED_TRACE(k.name());
    const ContactSet s = random_contacts(k.contacts, k.particles, k.pinned, 7 + k.contacts);
    auto got = jones_plassmann_coloring(s.particles, s.movable, k.colors, k.rounds);
    ASSERT_TRUE(got.ok()) << got.error().message();
    EXPECT_TRUE(capped_coloring_is_valid(*got, s.particles, s.movable, k.colors));
    EXPECT_EQ(std::accumulate(got->color_sizes.begin(), got->color_sizes.end(), 0u), k.contacts);
    expect_greedy_in_priority_order(s, *got, k.colors);
  }
}

// A tight cap sends contacts to the overflow set; few rounds leave
// contacts undecided, which join it too and are counted apart.
TEST(JonesPlassmann, OverflowIsCountedWhetherForColoursOrForRounds) {
  const ContactSet s = random_contacts(2000, 1000, 0.0, 11);
  auto roomy = jones_plassmann_coloring(s.particles, s.movable, 128, 254);
  ASSERT_TRUE(roomy.ok());
  EXPECT_EQ(roomy->color_sizes.back(), 0u) << "128 colours hold this set";
  EXPECT_EQ(roomy->out_of_rounds, 0u);
  const std::uint32_t needed = roomy->used_colors();
  auto capped = jones_plassmann_coloring(s.particles, s.movable, needed / 2, 254);
  ASSERT_TRUE(capped.ok());
  EXPECT_GT(capped->color_sizes.back(), 0u) << "half the colours it needs: some contacts overflow";
  EXPECT_EQ(capped->out_of_rounds, 0u);
  ASSERT_GT(roomy->rounds_needed, 2u);
  auto short_rounds = jones_plassmann_coloring(s.particles, s.movable, 128, roomy->rounds_needed - 1);
  ASSERT_TRUE(short_rounds.ok());
  EXPECT_GT(short_rounds->out_of_rounds, 0u);
  EXPECT_EQ(short_rounds->color_sizes.back(), short_rounds->out_of_rounds);
  auto exact_rounds = jones_plassmann_coloring(s.particles, s.movable, 128, roomy->rounds_needed);
  ASSERT_TRUE(exact_rounds.ok());
  EXPECT_EQ(exact_rounds->out_of_rounds, 0u);
  EXPECT_EQ(exact_rounds->color_of, roomy->color_of);
}

TEST(JonesPlassmann, BadInputIsNamed) {
  const std::vector<std::uint8_t> movable(4, 1);
  const std::vector<std::uint32_t> five{0, 1, 2, 3, 0};
  const std::vector<std::uint32_t> past{0, 1, 2, 4};
  const std::vector<std::uint32_t> one{0, 1, 2, 3};
  const auto message = [&](std::span<const std::uint32_t> p, std::uint32_t colors, std::uint32_t rounds) {
    auto r = jones_plassmann_coloring(p, movable, colors, rounds);
    EXPECT_FALSE(r.ok());
    return r.ok() ? std::string() : r.error().message();
  };
  EXPECT_NE(message(five, 8, 8).find("not 4 per contact"), std::string::npos);
  EXPECT_NE(message(past, 8, 8).find("particle 4"), std::string::npos);
  EXPECT_NE(message(one, 0, 8).find("cap of 0"), std::string::npos);
  EXPECT_NE(message(one, 129, 8).find("cap of 129"), std::string::npos);
  EXPECT_NE(message(one, 8, 0).find("0 rounds"), std::string::npos);
  EXPECT_NE(message(one, 8, 255).find("255 rounds"), std::string::npos);
}

// One colouring on a device: the table, the order and the colours read back.
struct DeviceRun {
  Status run;
  CappedColoring coloring;
  std::vector<std::uint32_t> order, table;
};

DeviceRun failed(Status why) {
  DeviceRun r;
  r.run = std::move(why);
  return r;
}

DeviceRun color_on(const std::string& backend, const ContactSet& s, std::uint32_t colors, std::uint32_t rounds,
                   std::uint32_t capacity = 0) {
  DeviceRun out;
  auto made = create_device({.backend = backend, .quiet = true});
  if (!made) return failed(made.error());
  Device& device = **made;
  const std::uint32_t n = s.contacts();
  if (capacity == 0) capacity = std::max(n, 1u);
  auto coloring = make_device_contact_coloring(device, capacity, static_cast<std::uint32_t>(s.movable.size()), colors,
                                               rounds);
  if (!coloring) return failed(coloring.error());
  std::vector<float> x(4 * s.movable.size(), 0.0f);
  for (std::size_t p = 0; p < s.movable.size(); ++p) x[4 * p + 3] = s.movable[p] ? 1.0f : 0.0f;
  auto positions = device.create_buffer(x.size() * 4, "positions");
  auto contacts = device.create_buffer(std::max<std::size_t>(capacity, n) * 16, "contacts");
  if (!positions || !contacts) return failed(Error(ErrorCode::internal, "buffers"));
  std::vector<std::uint32_t> particles = s.particles;
  particles.resize(std::size_t{std::max(capacity, n)} * 4, 0);
  if (Status st = device.write_buffer(*positions, 0, x.data(), x.size() * 4); !st) return failed(st);
  if (Status st = device.write_buffer(*contacts, 0, particles.data(), particles.size() * 4); !st) return failed(st);
  if (Status st = device.write_buffer(coloring->table, std::size_t{coloring->count_word()} * 4, &n, 4); !st) return failed(st);
  FrameProgram program;
  append_device_contact_coloring(program, *coloring, *contacts, *positions);
  auto prepared = device.create_program(program);
  if (!prepared) return failed(prepared.error());
  out.run = device.run_program(*prepared);
  if (!out.run) return out;
  auto read = read_device_contact_coloring(device, *coloring, &out.order);
  if (!read) return failed(read.error());
  out.coloring = std::move(*read);
  out.table.resize(coloring->table_words());
  out.run = device.read_buffer(coloring->table, 0, out.table.data(), out.table.size() * 4);
  return out;
}

class DeviceContactColoringTest : public BackendTest {};

void expect_equal_to_reference(const ContactSet& s, const DeviceRun& got, std::uint32_t colors, std::uint32_t rounds) {
  auto want = jones_plassmann_coloring(s.particles, s.movable, colors, rounds);
  ASSERT_TRUE(want.ok()) << want.error().message();
  ASSERT_TRUE(got.run.ok()) << got.run.error().message();
  EXPECT_TRUE(capped_coloring_is_valid(got.coloring, s.particles, s.movable, colors));
  EXPECT_EQ(got.coloring.color_of, want->color_of);
  EXPECT_EQ(got.coloring.color_sizes, want->color_sizes);
  EXPECT_EQ(got.coloring.out_of_rounds, want->out_of_rounds);
  // Within a colour, the contacts in increasing index (the sort is stable).
  const std::uint32_t c = colors + 1;
  for (std::uint32_t k = 0; k < c; ++k)
    for (std::uint32_t slot = got.table[c + k] + 1; slot < got.table[c + k] + got.table[k]; ++slot)
      ASSERT_LT(got.order[slot - 1], got.order[slot]) << "colour " << k;
}

// On random sets (dense and sparse, pinned particles, repeated particles,
// a cap that overflows, rounds that run out) the device's colouring is
// the reference's, contact for contact, and every backend's table and
// order are the CPU reference kernels' words.
TEST_P(DeviceContactColoringTest, EqualsTheSequentialReferenceOnRandomSets) {
  for (const RandomCase& k : {RandomCase{5000, 8000, 0.1, 64, 64}, RandomCase{4000, 500, 0.2, 16, 254},
                              RandomCase{3000, 300, 0.0, 128, 10}, RandomCase{700, 50, 0.5, 33, 254},
                              RandomCase{1, 4, 0.0, 1, 1}, RandomCase{0, 4, 0.0, 8, 8}}) {
    SCOPED_TRACE(k.name());
    const ContactSet s = random_contacts(k.contacts, k.particles, k.pinned, 3 + k.contacts);
    const DeviceRun got = color_on(GetParam(), s, k.colors, k.rounds);
    expect_equal_to_reference(s, got, k.colors, k.rounds);
    if (GetParam() != "cpu") {
      const DeviceRun cpu = color_on("cpu", s, k.colors, k.rounds);
      ASSERT_TRUE(cpu.run.ok());
      EXPECT_EQ(got.table, cpu.table);
      EXPECT_EQ(got.order, cpu.order);
    }
  }
}

// The real contacts of the kidney_57k surface bent so that its folds touch
// (the narrow phase's vertex-triangle and edge-edge contacts at a third of
// the mean edge; all of them, or pruned to the nearest few as the solver
// keeps them), all its vertices movable at a cap of 64, or its lowest fifth
// pinned at a cap of 12 that it overflows: the reference's colouring on every backend, the
// same words as the CPU's; the overflow named in the table.
TEST_P(DeviceContactColoringTest, EqualsTheReferenceOnTheBentKidneysContacts) {
  struct KidneyCase {
    bool pruned;
    double pinned;
    std::uint32_t colors;
  };
  for (const KidneyCase& k : {KidneyCase{false, 0.0, 64}, KidneyCase{false, 0.2, 12}, KidneyCase{true, 0.0, 64}}) {
    const ContactSet s = kidney_contacts(SINEW_DATA_DIR, 1.0f / 3.0f, k.pinned, k.pruned);
    ASSERT_GT(s.contacts(), 1000u) << "the bend should bring the kidney's folds within the thickness";
    SCOPED_TRACE(std::string(k.pruned ? "pruned" : "all") + ", pinned " + std::to_string(k.pinned) + ", cap " +
                 std::to_string(k.colors));
    constexpr std::uint32_t rounds = 96;
    const DeviceRun got = color_on(GetParam(), s, k.colors, rounds);
    expect_equal_to_reference(s, got, k.colors, rounds);
    if (GetParam() != "cpu") {
      const DeviceRun cpu = color_on("cpu", s, k.colors, rounds);
      ASSERT_TRUE(cpu.run.ok());
      EXPECT_EQ(got.table, cpu.table);
      EXPECT_EQ(got.order, cpu.order);
    }
    auto reference = jones_plassmann_coloring(s.particles, s.movable, k.colors, rounds);
    ASSERT_TRUE(reference.ok());
    std::printf("[ contact colouring ] %s: kidney %u contacts (%s, pinned %.0f%%), cap %u: %u colours, %u in the "
                "overflow set (%u out of rounds), %u rounds used\n",
                GetParam().c_str(), s.contacts(), k.pruned ? "pruned" : "all", 100.0 * k.pinned, k.colors, got.coloring.used_colors(),
                got.coloring.color_sizes.back(), got.coloring.out_of_rounds, reference->rounds_needed);
    if (k.colors == 12u) {
      EXPECT_GT(got.coloring.color_sizes.back(), 0u) << "12 colours should not hold this set";
    }
  }
}

// The contacts' summed violation [mesh units]: thickness - C summed over the
// contacts inside the thickness that move a particle, C = n . sum_k c_k x_k
// (mesh_contact_params.h); those of pinned particles only cannot change.
double summed_violation(const ContactSet& s, const std::vector<float>& x) {
  double sum = 0.0;
  for (std::uint32_t c = 0; c < s.contacts(); ++c) {
    double gap = 0.0;
    bool moves = false;
    for (int k = 0; k < 4; ++k) {
      moves = moves || s.movable[s.particles[4 * c + k]] != 0;
      for (int a = 0; a < 3; ++a)
        gap += double(s.normals[4 * c + a]) * s.coefficients[4 * c + k] * x[4 * s.particles[4 * c + k] + a];
    }
    if (moves) sum += std::max(0.0, double(s.thickness) - gap);
  }
  return sum;
}

// Sweeps of the kidney's contacts, solved as the device coloured them.
struct SolveRun {
  Status run;
  std::vector<float> x, lambda;  // positions; lambdas per contact
  std::vector<std::uint32_t> order, table;
};

// `sweeps` sweeps of xpbd_solve_mesh_contacts over the contacts of `s`
// (compliance 0, no friction, the frame's first substep). Device-coloured:
// the colouring, then per sweep the colours through its order and the
// overflow set serially (program/xpbd_program.h). Host layout (`order` and
// `table` given, from a device-coloured run): the contacts written slot by
// slot in that order and solved without it, as the host's colours are.
SolveRun solve_on(const std::string& backend, const ContactSet& s, std::uint32_t colors, int sweeps,
                  const std::vector<std::uint32_t>* order = nullptr, const std::vector<std::uint32_t>* table = nullptr) {
  SolveRun out;
  const auto fail = [&](Status why) {
    out.run = std::move(why);
    return out;
  };
  auto made = create_device({.backend = backend, .quiet = true});
  if (!made) return fail(made.error());
  Device& device = **made;
  const std::uint32_t n = s.contacts();
  const bool host_layout = order != nullptr;
  // Slot k holds contact at[k] (the host layout) or contact k.
  std::vector<std::uint32_t> at(n);
  std::iota(at.begin(), at.end(), 0u);
  if (host_layout) at = *order;
  std::vector<std::uint32_t> particles;
  std::vector<float> coefficients, normals;
  for (std::uint32_t k = 0; k < n; ++k)
    for (int j = 0; j < 4; ++j) {
      particles.push_back(s.particles[4 * at[k] + j]);
      coefficients.push_back(s.coefficients[4 * at[k] + j]);
      normals.push_back(s.normals[4 * at[k] + j]);
    }
  XpbdBuffers scene;
  MeshContactBuffers contacts;
  const auto buffer = [&](BufferHandle& h, const void* data, std::size_t bytes) -> Status {
    auto b = device.create_buffer(std::max<std::size_t>(bytes, 16), "case");
    if (!b) return b.error();
    h = *b;
    return data ? device.write_buffer(h, 0, data, bytes) : Status{};
  };
  const std::size_t contact_bytes = std::size_t{n} * 16;
  for (Status st : {buffer(scene.position, s.positions.data(), s.positions.size() * 4),
                    buffer(scene.previous, s.positions.data(), s.positions.size() * 4),
                    buffer(contacts.particles, particles.data(), contact_bytes),
                    buffer(contacts.coefficients, coefficients.data(), contact_bytes),
                    buffer(contacts.normals, normals.data(), contact_bytes),
                    buffer(contacts.lambda, nullptr, contact_bytes), buffer(contacts.lambda_sum, nullptr, contact_bytes),
                    buffer(contacts.motion, nullptr, contact_bytes / 4)})
    if (!st) return fail(st);
  kernels::MeshContactParams m{};
  m.thickness = s.thickness;
  m.inv_h2 = 3600.0f;
  m.substep_end = 1.0f;
  FrameProgram program;
  std::optional<DeviceContactColoring> coloring;
  DeviceColorTable colored;
  std::vector<std::uint32_t> counters;
  if (host_layout) {
    if (Status st = buffer(colored.table, table->data(), table->size() * 4); !st) return fail(st);
    colored.order = colored.table;  // unread: m.ordered stays 0
    for (std::uint32_t k = 0; k < colors; ++k)
      counters.push_back(program.counter("colour " + std::to_string(k), colored.table, k, n));
  } else {
    auto made_coloring =
        make_device_contact_coloring(device, n, static_cast<std::uint32_t>(s.movable.size()), colors, 128);
    if (!made_coloring) return fail(made_coloring.error());
    coloring = *made_coloring;
    if (Status st = device.write_buffer(coloring->table, std::size_t{coloring->count_word()} * 4, &n, 4); !st)
      return fail(st);
    append_device_contact_coloring(program, *coloring, contacts.particles, scene.position);
    colored = {coloring->table, coloring->order, colors, n};
    counters = declare_device_color_counters(program, colored);
  }
  for (int sweep = 0; sweep < sweeps; ++sweep) {
    m.reset_lambda = sweep == 0 ? 2u : 0u;
    if (!host_layout) {
      append_device_colored_sweep(program, scene, contacts, colored, counters, m);
      continue;
    }
    // The same dispatches without the order: the contacts are in slot order.
    m.colors = colors + 1;
    append_contact_colors(program, scene, contacts, colored.table, colored.order, counters, m);
    append_serial_contact_color(program, scene, contacts, colored.table, colored.order, colors, m);
  }
  auto prepared = device.create_program(program);
  if (!prepared) return fail(prepared.error());
  if (Status st = device.run_program(*prepared); !st) return fail(st);
  out.x.resize(s.positions.size());
  std::vector<float> lambda(std::size_t{n} * 4);
  if (Status st = device.read_buffer(scene.position, 0, out.x.data(), out.x.size() * 4); !st) return fail(st);
  if (Status st = device.read_buffer(contacts.lambda, 0, lambda.data(), lambda.size() * 4); !st) return fail(st);
  out.lambda.resize(lambda.size());
  for (std::uint32_t k = 0; k < n; ++k)  // per contact, whatever the slot
    std::copy_n(&lambda[4 * std::size_t{k}], 4, &out.lambda[4 * std::size_t{at[k]}]);
  if (coloring) {
    auto read = read_device_contact_coloring(device, *coloring, &out.order);
    if (!read) return fail(read.error());
    out.table.resize(2 * (colors + 1));
    if (Status st = device.read_buffer(coloring->table, 0, out.table.data(), out.table.size() * 4); !st) return fail(st);
  }
  return out;
}

// The solve reads the contacts the device coloured: each colour an
// indirect dispatch over its count on the device, the slots read through
// the colouring's order, the overflow set solved after the colours by one
// item. The bent kidney's contacts, pinned lowest fifth, at a cap of 12
// (thousands in the overflow set): after 10 sweeps the positions and the
// multipliers are bitwise those of the same dispatches over the contacts
// laid out slot by slot in that order (the host's layout, no order), equal
// on every backend, and the contacts' summed violation has shrunk to less
// than half.
TEST_P(DeviceContactColoringTest, TheSolveReadsTheDevicesColouring) {
  const ContactSet s = kidney_contacts(SINEW_DATA_DIR, 1.0f / 3.0f, 0.2);
  ASSERT_GT(s.contacts(), 1000u);
  constexpr std::uint32_t colors = 12;
  constexpr int sweeps = 10;
  const SolveRun got = solve_on(GetParam(), s, colors, sweeps);
  ASSERT_TRUE(got.run.ok()) << got.run.error().message();
  ASSERT_GT(got.table[colors], 0u) << "a cap of 12 should leave contacts to the overflow set";
  const SolveRun host = solve_on(GetParam(), s, colors, sweeps, &got.order, &got.table);
  ASSERT_TRUE(host.run.ok()) << host.run.error().message();
  EXPECT_EQ(got.x, host.x);
  EXPECT_EQ(got.lambda, host.lambda);
  if (GetParam() != "cpu") {
    const SolveRun cpu = solve_on("cpu", s, colors, sweeps);
    ASSERT_TRUE(cpu.run.ok());
    EXPECT_EQ(got.x, cpu.x);
    EXPECT_EQ(got.lambda, cpu.lambda);
  }
  const double before = summed_violation(s, s.positions), after = summed_violation(s, got.x);
  std::printf("[ contact colouring ] %s: %u contacts, %u in the overflow set; summed violation %.4g -> %.4g "
              "(thickness %.4g, mesh units) after %d sweeps\n",
              GetParam().c_str(), s.contacts(), got.table[colors], before, after, double(s.thickness), sweeps);
  EXPECT_LT(after, 0.5 * before);
}

// More contacts than the capacity: a capacity_exceeded error naming the
// contacts to colour, with their number.
TEST_P(DeviceContactColoringTest, MoreContactsThanTheCapacityIsANamedError) {
  const ContactSet s = random_contacts(300, 400, 0.0, 5);
  const DeviceRun got = color_on(GetParam(), s, 16, 16, 200);
  ASSERT_FALSE(got.run.ok());
  EXPECT_EQ(got.run.error().code(), ErrorCode::capacity_exceeded);
  EXPECT_NE(got.run.error().message().find("contacts to colour"), std::string::npos) << got.run.error().message();
  EXPECT_NE(got.run.error().message().find("300"), std::string::npos) << got.run.error().message();
}

// An overflow set larger than one invocation's loop can solve on every
// device (lavapipe breaks loops after 65,535 iterations) is a named error,
// not a partial serial pass: 62,000 contacts on 64 particles at a cap of one
// colour leave almost all of them to the overflow set.
TEST_P(DeviceContactColoringTest, AnOverflowSetTooLargeToSolveIsANamedError) {
  const ContactSet s = random_contacts(62000, 64, 0.0, 11);
  const DeviceRun got = color_on(GetParam(), s, 1, 4);
  ASSERT_FALSE(got.run.ok());
  EXPECT_EQ(got.run.error().code(), ErrorCode::capacity_exceeded);
  EXPECT_NE(got.run.error().message().find("contacts in the overflow set"), std::string::npos)
      << got.run.error().message();
  EXPECT_NE(got.run.error().message().find("of capacity 60000"), std::string::npos) << got.run.error().message();
}

TEST_P(DeviceContactColoringTest, BadSettingsAreNamed) {
  auto device = create_device({.backend = GetParam(), .quiet = true});
  ASSERT_TRUE(device.ok());
  const auto message = [&](std::uint32_t capacity, std::uint32_t particles, std::uint32_t colors, std::uint32_t rounds) {
    auto made = make_device_contact_coloring(**device, capacity, particles, colors, rounds);
    EXPECT_FALSE(made.ok());
    return made.ok() ? std::string() : made.error().message();
  };
  EXPECT_NE(message(0, 10, 8, 8).find("capacity of 0"), std::string::npos);
  EXPECT_NE(message((1u << 24) + 1, 10, 8, 8).find("capacity"), std::string::npos);
  EXPECT_NE(message(10, 0, 8, 8).find("no particles"), std::string::npos);
  EXPECT_NE(message(10, 10, 200, 8).find("cap of 200"), std::string::npos);
  EXPECT_NE(message(10, 10, 8, 300).find("300 rounds"), std::string::npos);
}

INSTANTIATE_TEST_SUITE_P(Backends, DeviceContactColoringTest, ::testing::ValuesIn(backends()), backend_name);

}  // namespace
}  // namespace sinew::test
