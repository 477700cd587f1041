// Image files in and out of nbsim, all through OpenImageIO (EXR, TIFF, PFM, PNG, ...), in a backend
// library loaded on first use (oiio_backend.h says why). Files are top-down; nbsim images are y up
// (model/common/depth.h): rows are flipped here. Every function throws InputError when the backend
// cannot be loaded, naming where it looked.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "model/common/depth.h"

namespace nbsim::io {

// Reads a single-channel depth image. Throws InputError naming the file when it cannot be read,
// has more than one channel, is empty, or holds a NaN, an infinity or a value outside [0, 1]
// (naming the first bad pixel, in y-up pixel coordinates and in file row order).
DepthImage read_depth(const std::filesystem::path& file);

// Reads a single-channel image of any values (NaN and infinities included: the caller checks them),
// e.g. a relief heightfield or safety-radius file. InputError naming the file as read_depth.
DepthImage read_values(const std::filesystem::path& file);

// Writes a float image as a single-channel 32-bit float file (EXR: channel "Z").
void write_depth(const DepthImage& image, const std::filesystem::path& file);

// Writes a 16-bit greyscale PNG preview that stretches [lo, hi] to black..white (lo == hi: grey).
void write_preview(const DepthImage& image, const std::filesystem::path& file, float lo, float hi);

// The OpenImageIO version the backend was built with.
std::string openimageio_version();

// Writes 8-bit RGB pixels (y up, row-major, 3 bytes a pixel) to any format OpenImageIO writes.
void write_rgb8(int width, int height, const std::vector<std::uint8_t>& rgb, const std::filesystem::path& file);

}  // namespace nbsim::io
