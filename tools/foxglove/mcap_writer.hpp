// A small MCAP writer (the container Foxglove and ROS 2 read): magic, Header, Schema and Channel
// records, Messages grouped into uncompressed Chunks with a CRC32 each, a Message Index per
// channel after every chunk, Data End with the data section's CRC32, then a summary section
// (Schemas, Channels, Statistics, Chunk Indexes) with Summary Offsets, the Footer with the
// summary's CRC32 and the closing magic. Debian packages no MCAP library; this follows the
// published specification (format version 0), record by record.
//
// Chunks are not compressed: a JSON point cloud is base64 of float32 and compresses poorly for
// what zstd/lz4 would cost per frame, and an uncompressed chunk needs no decoder on the reading
// side.
#pragma once

#include <cstdint>
#include <cstdio>
#include <map>
#include <string>
#include <string_view>
#include <vector>

namespace dlslot::mcap {

// The record opcodes of the specification.
enum Opcode : uint8_t {
  kHeader = 0x01, kFooter = 0x02, kSchema = 0x03, kChannel = 0x04, kMessage = 0x05, kChunk = 0x06,
  kMessageIndex = 0x07, kChunkIndex = 0x08, kStatistics = 0x0B, kSummaryOffset = 0x0E, kDataEnd = 0x0F,
};

// "\x89MCAP0\r\n": begins and ends every file.
inline constexpr char kMagic[8] = {'\x89', 'M', 'C', 'A', 'P', '0', '\r', '\n'};

// CRC-32 (ISO-HDLC, the one zlib and the specification use) of `size` bytes, continuing `crc`.
uint32_t crc32(uint32_t crc, const void* data, size_t size);

// Little-endian serialisation of the specification's field types into a byte string.
class Bytes {
 public:
  std::string& str() { return s_; }
  const std::string& str() const { return s_; }
  void u8(uint8_t v) { s_.push_back(static_cast<char>(v)); }
  void u16(uint16_t v) { le(v, 2); }
  void u32(uint32_t v) { le(v, 4); }
  void u64(uint64_t v) { le(v, 8); }
  void string(std::string_view v) {  // uint32 length + bytes
    u32(static_cast<uint32_t>(v.size()));
    s_.append(v.data(), v.size());
  }
  void raw(std::string_view v) { s_.append(v.data(), v.size()); }
  // A map/array: uint32 byte length, filled in by endLength().
  size_t beginLength() {
    u32(0);
    return s_.size();
  }
  void endLength(size_t start);
  // A record: opcode + uint64 content length (filled in by endRecord()).
  size_t beginRecord(uint8_t op) {
    u8(op);
    u64(0);
    return s_.size();
  }
  void endRecord(size_t start);

 private:
  void le(uint64_t v, int n) {
    for (int i = 0; i < n; ++i) s_.push_back(static_cast<char>((v >> (8 * i)) & 0xFF));
  }
  std::string s_;
};

struct WriterOptions {
  std::string profile;                 // "" (no well-known profile: JSON messages)
  std::string library = "dlslot-mcap";
  size_t chunk_size = 4 << 20;         // close a chunk once its records reach this many bytes
};

// Writes one MCAP file. Throws std::runtime_error naming the path when it cannot be written.
class Writer {
 public:
  Writer(const std::string& path, WriterOptions options = {});
  ~Writer();  // closes the file (without throwing) when close() was not called
  Writer(const Writer&) = delete;
  Writer& operator=(const Writer&) = delete;

  // Ids start at 1 (a schema id of 0 means "no schema").
  uint16_t addSchema(const std::string& name, const std::string& encoding, const std::string& data);
  uint16_t addChannel(uint16_t schema_id, const std::string& topic, const std::string& message_encoding,
                      const std::map<std::string, std::string>& metadata = {});
  // log_time and publish_time in nanoseconds. `sequence` defaults to the channel's running count.
  void write(uint16_t channel_id, uint64_t log_time, uint64_t publish_time, std::string_view data);
  // Flushes the last chunk and writes the summary, footer and closing magic.
  void close();

  uint64_t messageCount() const { return message_count_; }
  uint64_t bytesWritten() const { return offset_; }

 private:
  struct Schema { uint16_t id; std::string name, encoding, data; };
  struct Channel { uint16_t id, schema_id; std::string topic, encoding; std::map<std::string, std::string> metadata; };
  struct ChunkIndex {
    uint64_t start_time, end_time, offset, length, index_length, size;
    std::map<uint16_t, uint64_t> index_offsets;
  };
  void put(const std::string& bytes);  // to the file, into the data CRC
  void put(const std::string& bytes, uint32_t bytes_crc);  // the same, the bytes' CRC known
  void flushChunk();
  static void schemaRecord(Bytes& b, const Schema& s);
  static void channelRecord(Bytes& b, const Channel& c);

  std::string path_;
  WriterOptions opt_;
  std::FILE* file_ = nullptr;
  uint64_t offset_ = 0;
  uint32_t data_crc_ = 0;
  std::vector<Schema> schemas_;
  std::vector<Channel> channels_;
  std::vector<uint32_t> sequence_;        // per channel id - 1
  std::map<uint16_t, uint64_t> counts_;   // messages per channel id
  std::vector<ChunkIndex> chunk_index_;
  // The open chunk: its records and message index; schemas and channels go into the chunk of
  // their first message (once per file), and all of them into the summary.
  Bytes chunk_;
  std::map<uint16_t, std::vector<std::pair<uint64_t, uint64_t>>> chunk_msg_index_;
  std::vector<bool> written_schema_, written_channel_;
  uint64_t chunk_start_ = 0, chunk_end_ = 0;
  bool chunk_has_messages_ = false;
  uint64_t message_count_ = 0, start_time_ = 0, end_time_ = 0;
  bool closed_ = false;
};

}  // namespace dlslot::mcap
