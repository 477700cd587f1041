// The records a depth trace holds: the frame's records (the model's scene types, model/scene/frame.h)
// and the file's own (chunk types, header properties, end marker). traces/FORMAT.md specifies the
// bytes. Every enum that reaches a file has a fixed underlying type and fixed values.
// Conventions: model/common/depth.h (window depth in [0, 1], y up, pixel centres at +0.5).
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "model/scene/frame.h"

namespace nbsim::trace {

// Chunk types, as four ASCII characters read little-endian ('HEAD' is stored as "HEAD").
constexpr std::uint32_t fourcc(const char (&s)[5]) {
  return static_cast<std::uint32_t>(static_cast<unsigned char>(s[0])) |
         static_cast<std::uint32_t>(static_cast<unsigned char>(s[1])) << 8 |
         static_cast<std::uint32_t>(static_cast<unsigned char>(s[2])) << 16 |
         static_cast<std::uint32_t>(static_cast<unsigned char>(s[3])) << 24;
}

enum class ChunkType : std::uint32_t {
  Header = fourcc("HEAD"),      // Properties; always the first chunk
  Scene = fourcc("SCEN"),       // SceneObjects; once, after the header
  FrameBegin = fourcc("FRAM"),  // FrameBegin
  Draw = fourcc("DRAW"),        // DrawRecord
  Depth = fourcc("DPTH"),       // DepthSnapshot
  Levels = fourcc("NBLV"),      // NBufferLevels (built by the GLSL shader)
  Truth = fourcc("TRTH"),       // GroundTruth
  FrameEnd = fourcc("FEND"),    // FrameEnd
  End = fourcc("END "),         // EndMarker; always the last chunk
  DrawBatch = fourcc("DRWS"),   // DrawBatch: consecutive DrawRecords of a frame (version 2)
  Stencil = fourcc("STNC"),     // StencilSnapshot (version 2)
  Light = fourcc("LGHT"),       // Camera: the frame's light (version 2)
};

// Key/value properties of the header, in order (GL_RENDERER, viewport, technique, seed, ...).
using Properties = std::vector<std::pair<std::string, std::string>>;

// The frame's records are the model's scene types (model/scene/frame.h); the trace stores them.
using scene::Aabb;
using scene::BoundsTest;
using scene::ClipControl;
using scene::CullFace;
using scene::DepthFunc;
using scene::DepthSnapshot;
using scene::DepthState;
using scene::DepthWhich;
using scene::DrawRecord;
using scene::DrawRole;
using scene::FrameBegin;
using scene::FrameEnd;
using scene::GlCounters;
using scene::GroundTruth;
using scene::NBufferLevels;
using scene::SceneObjects;
using scene::TestMode;
using scene::Camera;
using scene::StencilFace;
using scene::StencilOp;
using scene::StencilSnapshot;
using scene::StencilState;
using scene::TechniqueField;
using scene::TechniqueRecord;
using scene::Topology;
using scene::to_string;

// A batch of a frame's consecutive draws in one chunk (version 2), so that zstd compresses them
// together; FEND.draws counts the draws, not the chunks.
struct DrawBatch {
  std::vector<DrawRecord> draws;
};

struct EndMarker {
  std::uint64_t chunks = 0;  // chunks before this one, header included
  std::uint32_t frames = 0;
};

}  // namespace nbsim::trace
