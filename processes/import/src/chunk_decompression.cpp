#include "livo/import/chunk_decompression.hpp"

#include <bzlib.h>
#include <lz4frame.h>
#include <zstd.h>

#include <algorithm>
#include <cstdio>

namespace livo::import {

namespace {

DecompressedChunk bz2(const uint8_t* in, size_t size, size_t expected) {
  DecompressedChunk out;
  out.data.resize(expected);
  bz_stream s{};
  if (BZ2_bzDecompressInit(&s, 0, 0) != BZ_OK) {
    out.data.clear();
    out.error = "bz2: cannot initialise the decompressor";
    return out;
  }
  s.next_in = const_cast<char*>(reinterpret_cast<const char*>(in));
  s.avail_in = static_cast<unsigned>(size);
  s.next_out = reinterpret_cast<char*>(out.data.data());
  s.avail_out = static_cast<unsigned>(expected);
  const int rc = BZ2_bzDecompress(&s);
  const size_t produced = expected - s.avail_out;
  BZ2_bzDecompressEnd(&s);
  out.data.resize(produced);
  if (rc == BZ_STREAM_END && produced == expected) {
    out.complete = true;
  } else if (rc == BZ_STREAM_END || rc == BZ_OK) {
    out.error = "bz2: stream gave " + std::to_string(produced) + " of " + std::to_string(expected) +
                " bytes (truncated chunk?)";
  } else {
    out.error = "bz2: corrupt data (error " + std::to_string(rc) + ") after " + std::to_string(produced) + " bytes";
  }
  return out;
}

DecompressedChunk lz4(const uint8_t* in, size_t size, size_t expected) {
  DecompressedChunk out;
  out.data.resize(expected);
  LZ4F_dctx* ctx = nullptr;
  if (LZ4F_isError(LZ4F_createDecompressionContext(&ctx, LZ4F_VERSION))) {
    out.data.clear();
    out.error = "lz4: cannot initialise the decompressor";
    return out;
  }
  size_t in_pos = 0, out_pos = 0;
  size_t hint = 1;
  while (in_pos < size && out_pos < expected && hint != 0) {
    size_t in_len = size - in_pos, out_len = expected - out_pos;
    hint = LZ4F_decompress(ctx, out.data.data() + out_pos, &out_len, in + in_pos, &in_len, nullptr);
    if (LZ4F_isError(hint)) {
      out.error = std::string("lz4: ") + LZ4F_getErrorName(hint) + " after " + std::to_string(out_pos) + " bytes";
      break;
    }
    in_pos += in_len;
    out_pos += out_len;
    if (in_len == 0 && out_len == 0) break;
  }
  LZ4F_freeDecompressionContext(ctx);
  out.data.resize(out_pos);
  if (out.error.empty()) {
    if (out_pos == expected)
      out.complete = true;
    else
      out.error = "lz4: frame gave " + std::to_string(out_pos) + " of " + std::to_string(expected) +
                  " bytes (truncated chunk?)";
  }
  return out;
}

}  // namespace

DecompressedChunk decompressZstd(const uint8_t* in, size_t size, size_t expected) {
  DecompressedChunk out;
  out.data.resize(expected);
  ZSTD_DStream* s = ZSTD_createDStream();
  if (!s) {
    out.data.clear();
    out.error = "zstd: cannot initialise the decompressor";
    return out;
  }
  ZSTD_inBuffer src{in, size, 0};
  ZSTD_outBuffer dst{out.data.data(), expected, 0};
  size_t rc = 1;
  while (rc != 0 && src.pos < src.size && dst.pos < dst.size) {
    const size_t before_in = src.pos, before_out = dst.pos;
    rc = ZSTD_decompressStream(s, &dst, &src);
    if (ZSTD_isError(rc)) {
      out.error = std::string("zstd: ") + ZSTD_getErrorName(rc) + " after " + std::to_string(dst.pos) + " bytes";
      break;
    }
    if (src.pos == before_in && dst.pos == before_out) break;
  }
  ZSTD_freeDStream(s);
  out.data.resize(dst.pos);
  if (out.error.empty()) {
    if (dst.pos == expected)
      out.complete = true;
    else
      out.error = "zstd: frame gave " + std::to_string(dst.pos) + " of " + std::to_string(expected) +
                  " bytes (truncated chunk?)";
  }
  return out;
}

DecompressedChunk decompressZstdFrame(const uint8_t* in, size_t size) {
  DecompressedChunk out;
  ZSTD_DStream* s = ZSTD_createDStream();
  if (!s) {
    out.error = "zstd: cannot initialise the decompressor";
    return out;
  }
  ZSTD_inBuffer src{in, size, 0};
  out.data.resize(std::max<size_t>(size * 4, 256));
  size_t rc = 1, produced = 0;
  while (rc != 0) {
    if (produced == out.data.size()) out.data.resize(out.data.size() * 2);
    ZSTD_outBuffer dst{out.data.data(), out.data.size(), produced};
    const size_t before_in = src.pos;
    rc = ZSTD_decompressStream(s, &dst, &src);
    const bool progressed = dst.pos != produced || src.pos != before_in;
    produced = dst.pos;
    if (ZSTD_isError(rc)) {
      out.error = std::string("zstd: ") + ZSTD_getErrorName(rc) + " after " + std::to_string(produced) + " bytes";
      break;
    }
    if (rc != 0 && !progressed && src.pos == src.size) {
      out.error = "zstd: the frame ends early after " + std::to_string(produced) + " bytes (truncated?)";
      break;
    }
  }
  ZSTD_freeDStream(s);
  out.data.resize(produced);
  out.complete = out.error.empty();
  return out;
}

std::string decompressZstdFile(const std::string& in_path, const std::string& out_path) {
  std::FILE* in = std::fopen(in_path.c_str(), "rb");
  if (!in) return in_path + ": cannot open";
  std::FILE* out = std::fopen(out_path.c_str(), "wb");
  if (!out) {
    std::fclose(in);
    return out_path + ": cannot write";
  }
  ZSTD_DStream* s = ZSTD_createDStream();
  std::vector<uint8_t> ibuf(ZSTD_DStreamInSize()), obuf(ZSTD_DStreamOutSize());
  std::string error;
  size_t rc = 1, got = 0, total = 0;
  while (error.empty() && (got = std::fread(ibuf.data(), 1, ibuf.size(), in)) > 0) {
    ZSTD_inBuffer src{ibuf.data(), got, 0};
    while (src.pos < src.size) {
      ZSTD_outBuffer dst{obuf.data(), obuf.size(), 0};
      rc = ZSTD_decompressStream(s, &dst, &src);
      if (ZSTD_isError(rc)) {
        error = in_path + ": zstd: " + ZSTD_getErrorName(rc) + " after " + std::to_string(total) + " bytes";
        break;
      }
      if (std::fwrite(obuf.data(), 1, dst.pos, out) != dst.pos) {
        error = out_path + ": write error";
        break;
      }
      total += dst.pos;
    }
  }
  if (error.empty() && rc != 0)
    error = in_path + ": zstd: the file ends inside a frame after " + std::to_string(total) + " bytes (truncated?)";
  ZSTD_freeDStream(s);
  std::fclose(in);
  if (std::fclose(out) != 0 && error.empty()) error = out_path + ": write error";
  return error;
}

DecompressedChunk decompressChunk(const std::string& compression, const uint8_t* in, size_t size,
                                  size_t expected_size) {
  if (compression == "none") {
    DecompressedChunk out;
    out.data.assign(in, in + std::min(size, expected_size));
    out.complete = size == expected_size;
    if (!out.complete)
      out.error = "uncompressed chunk holds " + std::to_string(size) + " bytes, its header says " +
                  std::to_string(expected_size) + " (truncated?)";
    return out;
  }
  if (compression == "bz2") return bz2(in, size, expected_size);
  if (compression == "lz4") return lz4(in, size, expected_size);
  DecompressedChunk out;
  out.error = "unknown chunk compression '" + compression + "'";
  return out;
}

}  // namespace livo::import
