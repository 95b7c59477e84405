#include "mcap_writer.hpp"

#include <zlib.h>

#include <cerrno>
#include <cstring>
#include <algorithm>
#include <limits>
#include <tuple>
#include <stdexcept>

namespace dlslot::mcap {

uint32_t crc32(uint32_t crc, const void* data, size_t size) {
  // zlib's crc32 takes uInt lengths: feed it in pieces.
  const auto* p = static_cast<const Bytef*>(data);
  while (size > 0) {
    const uInt n = static_cast<uInt>(std::min<size_t>(size, std::numeric_limits<uInt>::max()));
    crc = static_cast<uint32_t>(::crc32(crc, p, n));
    p += n;
    size -= n;
  }
  return crc;
}

void Bytes::endLength(size_t start) {
  const uint64_t n = s_.size() - start;
  if (n > std::numeric_limits<uint32_t>::max()) throw std::length_error("MCAP: a map or array over 4 GiB");
  for (int i = 0; i < 4; ++i) s_[start - 4 + i] = static_cast<char>((n >> (8 * i)) & 0xFF);
}

void Bytes::endRecord(size_t start) {
  const uint64_t n = s_.size() - start;
  for (int i = 0; i < 8; ++i) s_[start - 8 + i] = static_cast<char>((n >> (8 * i)) & 0xFF);
}

Writer::Writer(const std::string& path, WriterOptions options) : path_(path), opt_(std::move(options)) {
  file_ = std::fopen(path.c_str(), "wb");
  if (!file_) throw std::runtime_error(path + ": cannot write (" + std::strerror(errno) + ")");
  Bytes b;
  b.raw(std::string_view(kMagic, sizeof kMagic));
  const size_t h = b.beginRecord(kHeader);
  b.string(opt_.profile);
  b.string(opt_.library);
  b.endRecord(h);
  put(b.str());
}

Writer::~Writer() {
  if (!closed_ && file_) {
    try {
      close();
    } catch (...) {
      std::fclose(file_);
    }
  }
}

void Writer::put(const std::string& bytes) { put(bytes, crc32(0, bytes.data(), bytes.size())); }

void Writer::put(const std::string& bytes, uint32_t bytes_crc) {
  if (std::fwrite(bytes.data(), 1, bytes.size(), file_) != bytes.size())
    throw std::runtime_error(path_ + ": write failed (" + std::strerror(errno) + ")");
  data_crc_ = static_cast<uint32_t>(crc32_combine(data_crc_, bytes_crc, static_cast<z_off_t>(bytes.size())));
  offset_ += bytes.size();
}

void Writer::schemaRecord(Bytes& b, const Schema& s) {
  const size_t r = b.beginRecord(kSchema);
  b.u16(s.id);
  b.string(s.name);
  b.string(s.encoding);
  b.string(s.data);  // uint32 length-prefixed bytes: the same layout as a string
  b.endRecord(r);
}

void Writer::channelRecord(Bytes& b, const Channel& c) {
  const size_t r = b.beginRecord(kChannel);
  b.u16(c.id);
  b.u16(c.schema_id);
  b.string(c.topic);
  b.string(c.encoding);
  const size_t m = b.beginLength();
  for (const auto& [k, v] : c.metadata) {
    b.string(k);
    b.string(v);
  }
  b.endLength(m);
  b.endRecord(r);
}

uint16_t Writer::addSchema(const std::string& name, const std::string& encoding, const std::string& data) {
  if (schemas_.size() >= 0xFFFE) throw std::length_error("MCAP: too many schemas");
  schemas_.push_back({static_cast<uint16_t>(schemas_.size() + 1), name, encoding, data});
  written_schema_.push_back(false);
  return schemas_.back().id;
}

uint16_t Writer::addChannel(uint16_t schema_id, const std::string& topic, const std::string& message_encoding,
                            const std::map<std::string, std::string>& metadata) {
  if (schema_id > schemas_.size()) throw std::invalid_argument("MCAP: channel " + topic + " names an unknown schema");
  if (channels_.size() >= 0xFFFE) throw std::length_error("MCAP: too many channels");
  channels_.push_back({static_cast<uint16_t>(channels_.size() + 1), schema_id, topic, message_encoding, metadata});
  written_channel_.push_back(false);
  sequence_.push_back(0);
  return channels_.back().id;
}

void Writer::write(uint16_t channel_id, uint64_t log_time, uint64_t publish_time, std::string_view data) {
  if (closed_) throw std::logic_error("MCAP: write after close");
  if (channel_id == 0 || channel_id > channels_.size()) throw std::invalid_argument("MCAP: unknown channel id");
  const Channel& ch = channels_[channel_id - 1];
  // A channel (and its schema) precedes its first message, inside the chunk that holds it.
  if (ch.schema_id != 0 && !written_schema_[ch.schema_id - 1]) {
    schemaRecord(chunk_, schemas_[ch.schema_id - 1]);
    written_schema_[ch.schema_id - 1] = true;
  }
  if (!written_channel_[channel_id - 1]) {
    channelRecord(chunk_, ch);
    written_channel_[channel_id - 1] = true;
  }
  chunk_msg_index_[channel_id].emplace_back(log_time, chunk_.str().size());
  const size_t r = chunk_.beginRecord(kMessage);
  chunk_.u16(channel_id);
  chunk_.u32(sequence_[channel_id - 1]++);
  chunk_.u64(log_time);
  chunk_.u64(publish_time);
  chunk_.raw(data);
  chunk_.endRecord(r);
  if (!chunk_has_messages_ || log_time < chunk_start_) chunk_start_ = log_time;
  if (!chunk_has_messages_ || log_time > chunk_end_) chunk_end_ = log_time;
  if (message_count_ == 0 || log_time < start_time_) start_time_ = log_time;
  if (message_count_ == 0 || log_time > end_time_) end_time_ = log_time;
  chunk_has_messages_ = true;
  ++message_count_;
  ++counts_[channel_id];
  if (chunk_.str().size() >= opt_.chunk_size) flushChunk();
}

void Writer::flushChunk() {
  const std::string& records = chunk_.str();
  if (records.empty()) return;
  ChunkIndex idx{};
  idx.start_time = chunk_has_messages_ ? chunk_start_ : 0;
  idx.end_time = chunk_has_messages_ ? chunk_end_ : 0;
  idx.offset = offset_;
  idx.size = records.size();
  // The chunk's fixed fields; the records follow without a copy.
  Bytes head;
  head.u8(kChunk);
  const uint64_t content = 8 + 8 + 8 + 4 + 4 + 8 + records.size();  // compression "" is 4 bytes
  head.u64(content);
  head.u64(idx.start_time);
  head.u64(idx.end_time);
  head.u64(records.size());
  const uint32_t records_crc = crc32(0, records.data(), records.size());
  head.u32(records_crc);
  head.string("");
  head.u64(records.size());
  put(head.str());
  // The records' CRC joins the data section's without a second pass over them.
  put(records, records_crc);
  idx.length = offset_ - idx.offset;
  // One Message Index per channel of the chunk: offsets into the chunk's records.
  Bytes index;
  for (const auto& [channel, entries] : chunk_msg_index_) {
    idx.index_offsets[channel] = offset_ + index.str().size();
    const size_t r = index.beginRecord(kMessageIndex);
    index.u16(channel);
    const size_t a = index.beginLength();
    for (const auto& [t, off] : entries) {
      index.u64(t);
      index.u64(off);
    }
    index.endLength(a);
    index.endRecord(r);
  }
  idx.index_length = index.str().size();
  put(index.str());
  chunk_index_.push_back(std::move(idx));
  chunk_ = Bytes();
  chunk_msg_index_.clear();
  chunk_has_messages_ = false;
}

void Writer::close() {
  if (closed_) return;
  flushChunk();
  {
    Bytes end;
    const size_t r = end.beginRecord(kDataEnd);
    end.u32(data_crc_);
    end.endRecord(r);
    put(end.str());
  }
  // The summary: records grouped by opcode, each group's place in a Summary Offset.
  const uint64_t summary_start = offset_;
  Bytes sum;
  std::vector<std::tuple<uint8_t, uint64_t, uint64_t>> groups;
  auto group = [&](uint8_t op, auto&& body) {
    const uint64_t start = summary_start + sum.str().size();
    body();
    const uint64_t len = summary_start + sum.str().size() - start;
    if (len > 0) groups.emplace_back(op, start, len);
  };
  group(kSchema, [&] {
    for (const auto& s : schemas_) schemaRecord(sum, s);
  });
  group(kChannel, [&] {
    for (const auto& c : channels_) channelRecord(sum, c);
  });
  group(kStatistics, [&] {
    const size_t r = sum.beginRecord(kStatistics);
    sum.u64(message_count_);
    sum.u16(static_cast<uint16_t>(schemas_.size()));
    sum.u32(static_cast<uint32_t>(channels_.size()));
    sum.u32(0);  // attachments
    sum.u32(0);  // metadata
    sum.u32(static_cast<uint32_t>(chunk_index_.size()));
    sum.u64(message_count_ ? start_time_ : 0);
    sum.u64(message_count_ ? end_time_ : 0);
    const size_t m = sum.beginLength();
    for (const auto& c : channels_) {  // every channel, those without messages at 0
      sum.u16(c.id);
      const auto it = counts_.find(c.id);
      sum.u64(it == counts_.end() ? 0 : it->second);
    }
    sum.endLength(m);
    sum.endRecord(r);
  });
  group(kChunkIndex, [&] {
    for (const auto& c : chunk_index_) {
      const size_t r = sum.beginRecord(kChunkIndex);
      sum.u64(c.start_time);
      sum.u64(c.end_time);
      sum.u64(c.offset);
      sum.u64(c.length);
      const size_t m = sum.beginLength();
      for (const auto& [ch, off] : c.index_offsets) {
        sum.u16(ch);
        sum.u64(off);
      }
      sum.endLength(m);
      sum.u64(c.index_length);
      sum.string("");
      sum.u64(c.size);  // compressed = uncompressed
      sum.u64(c.size);
      sum.endRecord(r);
    }
  });
  const uint64_t summary_offset_start = summary_start + sum.str().size();
  for (const auto& [op, start, len] : groups) {
    const size_t r = sum.beginRecord(kSummaryOffset);
    sum.u8(op);
    sum.u64(start);
    sum.u64(len);
    sum.endRecord(r);
  }
  // Footer: its CRC covers the summary, the summary offsets and the footer up to the CRC field.
  sum.u8(kFooter);
  sum.u64(8 + 8 + 4);
  sum.u64(summary_start);
  sum.u64(summary_offset_start);
  sum.u32(crc32(0, sum.str().data(), sum.str().size()));
  sum.raw(std::string_view(kMagic, sizeof kMagic));
  put(sum.str());
  closed_ = true;
  const bool flushed = std::fflush(file_) == 0;
  const bool ok = std::fclose(file_) == 0 && flushed;
  file_ = nullptr;
  if (!ok) throw std::runtime_error(path_ + ": write failed (" + std::strerror(errno) + ")");
}

}  // namespace dlslot::mcap
