// The layered-depth-image technique (Trapp & Doellner) on the capture side: `nbsim capture ldi`.
// Per frame, the shape (--shape from model/mesh/shapes.h, or --mesh FILE read with mesh_loader.h and
// refused unless closed) is rotated (frame 0: identity; later frames: a random rotation from --seed
// and the frame index), fitted into the unit cube (normalize_to_unit_cube, margin 0: it touches the
// two faces of its longest axis), and built on GL by build.h: viewpoint selection over the
// --grid, depth peeling at the chosen direction (every pass a draw of role LdiPeel), crop and
// compression. Then --points test points (test_points.h) get GL's parity answers from both readers
// (shaders/ldi/vpt.comp) and the exact reference. Records: the peel draws, LDIL and LDIT
// (traces/format/ldi/ldi_chunk.h).
// The observer is not used: the scene, the camera path and --size only satisfy the capture driver
// (the header says so in `observer`); no scene is built. --application clip or lens (clip.h) draws a scene instead.
#pragma once

#include <memory>
#include <vector>

#include "traces/capture/plugin.h"
#include "traces/capture/technique.h"

namespace nbsim::capture {

// --shape, --shape-param, --mesh, --ldi-size, --grid, --max-layers, --points, --epsilon, --seed.
const std::vector<OptionSpec>& ldi_options();

// Reads and checks the options and the shape (an unusable mesh file is an InputError here, before
// any output file exists).
std::unique_ptr<Technique> make_ldi(const TechniqueSetup& setup);
// Its `nbsim bench replay` workload.
BenchPreset ldi_bench_preset();

}  // namespace nbsim::capture
