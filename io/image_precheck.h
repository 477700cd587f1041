// What nbsim checks in a depth image file before OpenImageIO opens it. OpenImageIO and the
// libraries under it (libpng, OpenEXR, libtiff) allocate what a header declares before they read
// it, and a file whose extension they do not recognise is offered to every reader OpenImageIO has
// (DICOM, video, camera raw, ...). fuzz_depth_image found both: a 400-byte PNG whose text chunk
// declared 1.8 GB, an EXR attribute of 1.8 GB, each costing gigabytes and many seconds before the
// read failed. So the format is recognised here by its magic bytes (EXR, TIFF, PNG, PFM only), and
// the structures that declare sizes (PNG chunks, EXR header attributes, TIFF directory entries,
// strips and tiles) are walked and checked against the file's length and nbsim's image size limit
// first. No OpenImageIO in here.
#pragma once

#include <string>

namespace nbsim::io {

// The largest buffer a file's declared layout may make a reader allocate beyond the image itself
// (a TIFF's RowsPerStrip above its rows sizes OpenImageIO's read buffer). OpenImageIO reads in
// chunks of about 64 MiB; 256 MiB leaves room for any layout a writer would choose. Tunable.
inline constexpr unsigned long long kMaxReadBufferBytes = 256ull << 20;

struct ImagePrecheck {
  std::string format;  // OpenImageIO's reader name ("openexr", "tiff", "png", "pnm"); empty when refused
  std::string refusal;  // why the file is refused (to follow the file's name), empty when accepted
};

// Checks the file at `path` (read only as far as its headers) against the formats nbsim reads and
// the limits of side and pixel count (oiio_backend.h kMaxDepthSide, kMaxDepthPixels).
ImagePrecheck precheck_depth_file(const std::string& path, long long max_side, long long max_pixels);

}  // namespace nbsim::io
