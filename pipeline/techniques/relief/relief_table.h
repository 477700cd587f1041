// `nbsim relief`'s table from replays of relief traces (plain C++, no SystemC): one row per trace,
// frame and method from run.json's per-frame relief values (pipeline/sim/replay.cpp), the ranking
// of the methods by cost (cycles and lookups per fragment) and error with the Pareto front, the
// N-buffer walk against the exact walk per heightfield, and the paper's Table 1 (Baboud & Decoret:
// frame rates of the terrain on a GeForce 6800 GT at 32^2 to 256^2) beside our cycles.
#pragma once

#include <nlohmann/json.hpp>

#include <string>
#include <vector>

namespace nbsim::techniques {

// Rows from each trace's run.json (runs[i] is traces[i]'s): trace, field, field_size, frame,
// angle, method, fragments, lookups, steps, errors, reference_hits, cycles, lookups_per_fragment,
// steps_per_fragment, error_rate, pixel_mismatches, walk_mismatches. Throws InputError naming a
// run.json that is not a relief replay.
nlohmann::ordered_json relief_rows(const std::vector<nlohmann::json>& runs, const std::vector<std::string>& traces);

// Per method over `rows`: fragments, lookups_per_fragment, steps_per_fragment, cycles_per_frame
// (mean over its rows), error_rate, errors, pareto (no other method is at most as costly in cycles
// and at most as wrong, and better in one), in order of cycles_per_frame.
nlohmann::ordered_json relief_ranking(const nlohmann::ordered_json& rows);

// Per (field, field_size): the exact and N-buffer walks' lookups per fragment and errors, the
// lookup ratio nbuffer / exact, and extra_errors = nbuffer errors - exact errors.
nlohmann::ordered_json relief_nbuffer_vs_exact(const nlohmann::ordered_json& rows);

// The paper's Table 1 terrain rows (frame rates, Hz) at 32, 64, 128, 256 for binary, exact and
// robust, with our cycles per frame of the fbm rows of the same size beside them where we have them.
nlohmann::ordered_json relief_paper_table(const nlohmann::ordered_json& rows);

}  // namespace nbsim::techniques
