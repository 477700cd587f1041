// The bytes of a trace (traces/FORMAT.md): the preamble, chunk framing (zstd, CRC-32) and the
// little-endian encoding of every record. TraceWriter and TraceReader sit on top of it.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "traces/format/records.h"
#include "traces/format/schema.h"

namespace nbsim::trace {

// The newest format version this build writes and reads (FORMAT.md's version table). Fixed by
// the format: bump it, and add a row to the table, whenever a byte changes meaning.
inline constexpr std::uint32_t kFormatVersion = 2;

// Fixed by the format (FORMAT.md "Preamble" and "Chunks").
inline constexpr std::array<std::uint8_t, 8> kMagic = {0x89, 'N', 'B', 'T', 'R', '\r', '\n', 0x1A};
inline constexpr std::size_t kPreambleBytes = 16;    // magic, version, CRC-32
inline constexpr std::size_t kChunkHeaderBytes = 24;  // type, flags, stored length, raw length
inline constexpr std::size_t kChunkCrcBytes = 4;
inline constexpr std::uint32_t kFlagZstd = 1;         // bit 0: the payload is one zstd frame
inline constexpr std::uint32_t kFlagTechnique = 2;    // bit 1 (version 2): a technique's chunk type (technique_chunks.h)
inline constexpr std::uint32_t kKnownFlagsV1 = kFlagZstd;
inline constexpr std::uint32_t kKnownFlags = kFlagZstd | kFlagTechnique;

// Tunable writer choices (not part of the format: any reader reads any choice). Payloads below
// 1 KiB rarely shrink; zstd level 3 (its default) compresses depth images ~3-10x at >100 MB/s.
// A frame's draws go in DRWS batches of at most kDrawsPerBatch draws or kBatchBytes payload bytes
// (whichever comes first): large enough for zstd to find the draws' shared structure, small
// enough to keep the writer's memory bounded. Measured on a 10-frame 512x512 city fly capture
// (3685 draws a frame), the draws' stored bytes per frame by batch size: 1 draw 1122 KB, 16 292 KB,
// 64 267 KB, 256 259 KB, 1024 259 KB, the whole frame 259 KB.
inline constexpr std::size_t kCompressMinBytes = 1024;
inline constexpr int kZstdLevel = 3;
inline constexpr std::size_t kDrawsPerBatch = 1024;
inline constexpr std::size_t kBatchBytes = std::size_t{4} << 20;

bool is_known_chunk_type(std::uint32_t type) noexcept;
// The format version that introduced a core chunk type, 0 for an unknown type.
std::uint32_t chunk_type_since(std::uint32_t type) noexcept;
// "DRAW" for a printable fourcc, else "0x1234abcd".
std::string chunk_type_name(std::uint32_t type);
inline std::string chunk_type_name(ChunkType type) { return chunk_type_name(static_cast<std::uint32_t>(type)); }

// CRC-32 as zlib computes it (polynomial 0xEDB88320, initial value 0), continued from `crc`.
std::uint32_t crc32(std::span<const std::uint8_t> bytes, std::uint32_t crc = 0) noexcept;

// The 16-byte preamble of a file of `version`.
std::array<std::uint8_t, kPreambleBytes> encode_preamble(std::uint32_t version);

// One framed chunk: header, payload (zstd-compressed when `compress` and it shrinks a payload of
// at least kCompressMinBytes) and CRC-32. The payload must be at most kMaxChunkBytes.
// `extra_flags` is 0 or kFlagTechnique.
std::vector<std::uint8_t> encode_chunk(ChunkType type, std::span<const std::uint8_t> payload, bool compress = true,
                                       std::uint32_t extra_flags = 0);

// Records -> payload bytes, in the layout of kFormatVersion. The record must be consistent
// (record_problem() empty); a record above kMaxChunkBytes is refused later by encode_chunk.
std::vector<std::uint8_t> encode(const Properties& properties);
std::vector<std::uint8_t> encode(const SceneObjects& scene);
std::vector<std::uint8_t> encode(const FrameBegin& frame);
std::vector<std::uint8_t> encode(const DrawRecord& draw);
std::vector<std::uint8_t> encode(const DepthSnapshot& depth);
std::vector<std::uint8_t> encode(const NBufferLevels& levels);
std::vector<std::uint8_t> encode(const GroundTruth& truth);
std::vector<std::uint8_t> encode(const FrameEnd& frame);
std::vector<std::uint8_t> encode(const EndMarker& end);
std::vector<std::uint8_t> encode(const DrawBatch& batch);
std::vector<std::uint8_t> encode(const StencilSnapshot& stencil);
std::vector<std::uint8_t> encode(const Camera& light);

// What makes a record impossible to store or read back ("" when it is consistent): mismatched
// vector sizes, an image size out of range, a bad property key, ... Decoders refuse the same.
std::string record_problem(const Properties& properties);
std::string record_problem(const SceneObjects& scene);
std::string record_problem(const FrameBegin& frame);
std::string record_problem(const DrawRecord& draw);
std::string record_problem(const DepthSnapshot& depth);
std::string record_problem(const NBufferLevels& levels);
std::string record_problem(const GroundTruth& truth);
std::string record_problem(const DrawBatch& batch);
std::string record_problem(const StencilSnapshot& stencil);
std::string record_problem(const Camera& light);

// Payload bytes of a file of `version` (1 ..= kFormatVersion) -> record. Each decoder switches on
// the version, so a later version can add fields while older files still read. Throws InputError
// saying what is wrong (a payload that decodes short or long, an enum value out of range, ...);
// TraceReader adds the file, chunk and byte offset.
Properties decode_properties(std::span<const std::uint8_t> payload, std::uint32_t version);
SceneObjects decode_scene(std::span<const std::uint8_t> payload, std::uint32_t version);
FrameBegin decode_frame_begin(std::span<const std::uint8_t> payload, std::uint32_t version);
DrawRecord decode_draw(std::span<const std::uint8_t> payload, std::uint32_t version);
DepthSnapshot decode_depth(std::span<const std::uint8_t> payload, std::uint32_t version);
NBufferLevels decode_levels(std::span<const std::uint8_t> payload, std::uint32_t version);
GroundTruth decode_truth(std::span<const std::uint8_t> payload, std::uint32_t version);
FrameEnd decode_frame_end(std::span<const std::uint8_t> payload, std::uint32_t version);
EndMarker decode_end(std::span<const std::uint8_t> payload, std::uint32_t version);
DrawBatch decode_draw_batch(std::span<const std::uint8_t> payload, std::uint32_t version);
StencilSnapshot decode_stencil(std::span<const std::uint8_t> payload, std::uint32_t version);
Camera decode_light(std::span<const std::uint8_t> payload, std::uint32_t version);

// The chunk type each record is stored in.
template <class Record> struct RecordChunk;
template <> struct RecordChunk<Properties> { static constexpr ChunkType type = ChunkType::Header; };
template <> struct RecordChunk<SceneObjects> { static constexpr ChunkType type = ChunkType::Scene; };
template <> struct RecordChunk<FrameBegin> { static constexpr ChunkType type = ChunkType::FrameBegin; };
template <> struct RecordChunk<DrawRecord> { static constexpr ChunkType type = ChunkType::Draw; };
template <> struct RecordChunk<DepthSnapshot> { static constexpr ChunkType type = ChunkType::Depth; };
template <> struct RecordChunk<NBufferLevels> { static constexpr ChunkType type = ChunkType::Levels; };
template <> struct RecordChunk<GroundTruth> { static constexpr ChunkType type = ChunkType::Truth; };
template <> struct RecordChunk<FrameEnd> { static constexpr ChunkType type = ChunkType::FrameEnd; };
template <> struct RecordChunk<EndMarker> { static constexpr ChunkType type = ChunkType::End; };
template <> struct RecordChunk<DrawBatch> { static constexpr ChunkType type = ChunkType::DrawBatch; };
template <> struct RecordChunk<StencilSnapshot> { static constexpr ChunkType type = ChunkType::Stencil; };
template <> struct RecordChunk<Camera> { static constexpr ChunkType type = ChunkType::Light; };

}  // namespace nbsim::trace
