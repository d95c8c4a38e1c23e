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
        std::fprintf(stderr, "%s (%s)\n", message, rbs_status_string(code));
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
    // many hits from the table, uniforms from rng
    rbs_hits hits = RBS_HITS_INIT;
    hits.count = count;
    hits.V = V.data();
    hits.n = n.data();
    hits.a = a.data();
    hits.rng = &rng;
    rbs_results results = RBS_RESULTS_INIT;
    results.V = V_out.data();
    results.Omega = Omega_out.data();
    results.status = status.data();
    rbs_options options = RBS_OPTIONS_INIT;
    options.interpolation = RBS_INTERPOLATION_STOCHASTIC;
    if (rbs_draw_many(table.get(), mix.get(), &hits, &options, &results) != RBS_OK) return 1;
    // one more hit, uniforms given
    std::array<double, RBS_U_PER_DRAW> u{};
    rbs_rng_fill(&rng, u.data(), u.size());
    rbs_hit hit = RBS_HIT_INIT;
    for (int k = 0; k < 3; k++) {
        hit.V[k] = V[k];
        hit.n[k] = n[k];
    }
    hit.a = 1e-4;
    hit.u = u.data();
    rbs_result result = RBS_RESULT_INIT;
    int st = rbs_rebound(table.get(), mix.get(), &hit, &options, &result);
    std::size_t rebounded = 0;
    for (signed char s : status) rebounded += s == RBS_OK;
    std::printf("C++: %zu of %zu rebounded over %d shapes; one more: status %d (%s); library %s (%d)\n", rebounded,
                count, rbs_table_n_shapes(table.get()), st, rbs_status_string(st), rbs_version(),
                rbs_version_number());
    return rebounded > 0 ? 0 : 1;
}
