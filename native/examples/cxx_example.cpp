// cxx_example.cpp: the C header used from C++ as it is (extern "C" guards); built by tests/native with g++.
//
//   cxx_example TABLE.h5
//
// Copyright (c) the rebound-scatter authors. BSD-3-Clause license.
#include <array>
#include <cstdio>
#include <memory>
#include <vector>

#include "rebound_scatter.h"

int main(int argc, char **argv)
{
    if (argc < 2) {
        std::fprintf(stderr, "usage: %s TABLE.h5\n", argv[0]);
        return 2;
    }
    char message[1024];
    rbs_table *raw = nullptr;
    if (int code = rbs_table_open(argv[1], &raw, message, sizeof message); code != RBS_OK) {
        std::fprintf(stderr, "%s (%s)\n", message, rbs_error_string(code));
        return 1;
    }
    std::unique_ptr<rbs_table, decltype(&rbs_table_close)> table(raw, &rbs_table_close);
    // the table's shapes, however many, with equal weights; freed with the table's lifetime's end
    std::unique_ptr<rbs_mix, decltype(&rbs_mix_free)> mix(rbs_mix_new_equal(table.get()), &rbs_mix_free);
    if (!mix) return 1;
    rbs_rng rng;
    rbs_rng_seed_stream(&rng, 1, 0);
    const std::size_t count = 100;
    std::vector<double> V(3 * count), n(3 * count, 0.0), a(count, 1e-4), V_out(3 * count), Omega_out(3 * count);
    std::vector<signed char> status(count);
    for (std::size_t i = 0; i < count; i++) {
        V[3 * i] = 100.0;
        V[3 * i + 1] = -60.0 - static_cast<double>(i);
        n[3 * i + 1] = 1.0;
    }
    rbs_table_rebound_many_rng(table.get(), mix.get(), count, V.data(), n.data(), a.data(), &rng, RBS_SCALED,
                               V_out.data(), Omega_out.data(), status.data());
    std::array<double, RBS_U_PER_DRAW> u{};
    rbs_rng_fill(&rng, u.data(), u.size());
    double one[3], spin[3];
    int st = rbs_table_rebound(table.get(), mix.get(), V.data(), n.data(), 1e-4, u.data(), RBS_STOCHASTIC, one, spin);
    std::size_t rebounded = 0;
    for (signed char s : status) rebounded += s == RBS_REBOUNDED;
    std::printf("C++: %zu of %zu rebounded over %d shapes; one more: status %d; library %s\n", rebounded, count,
                rbs_table_n_shapes(table.get()), st, rbs_version());
    return rebounded > 0 ? 0 : 1;
}
