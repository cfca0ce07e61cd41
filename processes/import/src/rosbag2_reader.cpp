#include "livo/import/rosbag2_reader.hpp"

#include <sqlite3.h>
#include <yaml-cpp/yaml.h>

#include <stdlib.h>
#include <unistd.h>

#include <cctype>
#include <cstdio>
#include <filesystem>
#include <memory>

#include "livo/import/chunk_decompression.hpp"
#include "livo/import/file_utils.hpp"
#include "livo/import/mcap_reader.hpp"

namespace livo::import {

namespace {

namespace fs = std::filesystem;

bool endsWith(const std::string& s, const std::string& tail) {
  return s.size() >= tail.size() && s.compare(s.size() - tail.size(), tail.size(), tail) == 0;
}

std::string storageOfFile(const std::string& file) {
  if (endsWith(file, ".mcap")) return "mcap";
  if (endsWith(file, ".db3")) return "sqlite3";
  return "";
}

/// metadata.yaml's rosbag2_bagfile_information: storage, files (relative to the directory) and
/// topics with their counts.
struct BagMetadata {
  std::string storage;
  std::string compression_mode;  // "", FILE or MESSAGE
  std::vector<std::string> files;
  std::vector<Rosbag2Topic> topics;
};

BagMetadata readMetadata(const std::string& dir) {
  const std::string path = (fs::path(dir) / "metadata.yaml").string();
  BagMetadata m;
  try {
    const YAML::Node info = YAML::LoadFile(path)["rosbag2_bagfile_information"];
    if (!info) throw Rosbag2Error(path + ": no rosbag2_bagfile_information (not a rosbag2 metadata.yaml)");
    m.storage = info["storage_identifier"].as<std::string>("");
    const std::string compression = info["compression_format"].as<std::string>("");
    if (!compression.empty()) {
      m.compression_mode = info["compression_mode"].as<std::string>("");
      for (char& c : m.compression_mode) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
      if (compression != "zstd" || (m.compression_mode != "FILE" && m.compression_mode != "MESSAGE"))
        throw Rosbag2Error(path + ": compression_format " + compression + ", compression_mode " + m.compression_mode +
                           ": not supported (zstd, FILE or MESSAGE)");
    }
    for (const YAML::Node& f : info["relative_file_paths"]) m.files.push_back((fs::path(dir) / f.as<std::string>()).string());
    for (const YAML::Node& t : info["topics_with_message_count"]) {
      const YAML::Node tm = t["topic_metadata"];
      Rosbag2Topic topic;
      topic.topic = tm["name"].as<std::string>("");
      topic.type = tm["type"].as<std::string>("");
      topic.serialization_format = tm["serialization_format"].as<std::string>("");
      topic.messages = t["message_count"].as<int64_t>(-1);
      m.topics.push_back(topic);
    }
  } catch (const YAML::Exception& e) {
    throw Rosbag2Error(path + ": " + e.what());
  }
  if (m.storage.empty() && !m.files.empty()) {
    std::string first = m.files.front();
    if (endsWith(first, ".zstd")) first.resize(first.size() - 5);
    m.storage = storageOfFile(first);
  }
  if (m.files.empty()) throw Rosbag2Error(path + ": relative_file_paths lists no file");
  return m;
}

/// A read-only SQLite database, closed on destruction.
struct Sqlite {
  sqlite3* db = nullptr;
  explicit Sqlite(const std::string& file) {
    if (sqlite3_open_v2(file.c_str(), &db, SQLITE_OPEN_READONLY, nullptr) != SQLITE_OK) {
      const std::string msg = db ? sqlite3_errmsg(db) : "out of memory";
      sqlite3_close(db);
      throw Rosbag2Error(file + ": cannot open as SQLite: " + msg);
    }
  }
  ~Sqlite() { sqlite3_close(db); }
  Sqlite(const Sqlite&) = delete;
  Sqlite& operator=(const Sqlite&) = delete;
};

struct Statement {
  sqlite3_stmt* s = nullptr;
  Statement(sqlite3* db, const char* sql, const std::string& file) {
    if (sqlite3_prepare_v2(db, sql, -1, &s, nullptr) != SQLITE_OK)
      throw Rosbag2Error(file + ": not a rosbag2 SQLite bag (" + sqlite3_errmsg(db) + " in: " + sql + ")");
  }
  ~Statement() { sqlite3_finalize(s); }
  Statement(const Statement&) = delete;
  Statement& operator=(const Statement&) = delete;
};

std::string text(sqlite3_stmt* s, int col) {
  const unsigned char* t = sqlite3_column_text(s, col);
  return t ? reinterpret_cast<const char*>(t) : "";
}

/// The topics table: id -> topic.
std::map<int64_t, Rosbag2Topic> sqliteTopics(sqlite3* db, const std::string& file) {
  Statement st(db, "SELECT id, name, type, serialization_format FROM topics", file);
  std::map<int64_t, Rosbag2Topic> topics;
  int rc;
  while ((rc = sqlite3_step(st.s)) == SQLITE_ROW) {
    Rosbag2Topic t;
    t.topic = text(st.s, 1);
    t.type = text(st.s, 2);
    t.serialization_format = text(st.s, 3);
    topics[sqlite3_column_int64(st.s, 0)] = t;
  }
  if (rc != SQLITE_DONE) throw Rosbag2Error(file + ": topics table: " + sqlite3_errmsg(db));
  return topics;
}

/// Topics of an MCAP file: its summary, else a full scan; counts from the Statistics record.
std::vector<Rosbag2Topic> mcapTopics(const std::string& file) {
  McapReader reader(file);
  McapSummary s = reader.readSummary();
  std::map<uint16_t, int64_t> counts;
  std::map<uint16_t, McapChannel> channels = s.channels;
  if (channels.empty() || !s.has_statistics) {
    try {
      reader.readAll([&](const McapMessage& m) { ++counts[m.channel->id]; });
    } catch (const McapError&) {
      // the import reports the damage; the channels before it are listed
    }
    channels = reader.channels();
  } else {
    for (const auto& [id, n] : s.message_counts) counts[id] = static_cast<int64_t>(n);
  }
  std::vector<Rosbag2Topic> topics;
  for (const auto& [id, c] : channels) topics.push_back({c.topic, c.schema_name, c.message_encoding, counts[id]});
  return topics;
}

}  // namespace

Rosbag2Reader::Rosbag2Reader(const std::string& input) {
  if (isDirectory(input)) {
    if (!isFile((fs::path(input) / "metadata.yaml").string()))
      throw Rosbag2Error(input + ": a directory without metadata.yaml (not a rosbag2 bag directory)");
    BagMetadata m = readMetadata(input);
    storage_ = m.storage;
    compression_mode_ = m.compression_mode;
    files_ = m.files;
    metadata_topics_ = m.topics;
  } else if (isFile(input)) {
    storage_ = storageOfFile(input);
    if (storage_.empty()) throw Rosbag2Error(input + ": neither a .mcap nor a .db3 file (nor a bag directory)");
    files_ = {input};
  } else {
    throw Rosbag2Error(input + ": no such file or directory");
  }
  if (storage_ != "mcap" && storage_ != "sqlite3")
    throw Rosbag2Error(input + ": storage '" + storage_ + "' is not supported (mcap, sqlite3)");
}

std::vector<Rosbag2Topic> Rosbag2Reader::topics() {
  if (!metadata_topics_.empty()) return metadata_topics_;
  std::map<std::string, Rosbag2Topic> by_name;
  for (const std::string& file : files_) {
    std::vector<Rosbag2Topic> found;
    if (storage_ == "mcap") {
      found = mcapTopics(file);
    } else {
      Sqlite db(file);
      std::map<int64_t, Rosbag2Topic> t = sqliteTopics(db.db, file);
      Statement st(db.db, "SELECT topic_id, COUNT(*) FROM messages GROUP BY topic_id", file);
      while (sqlite3_step(st.s) == SQLITE_ROW) t[sqlite3_column_int64(st.s, 0)].messages = sqlite3_column_int64(st.s, 1);
      for (auto& kv : t) found.push_back(kv.second);
    }
    for (const Rosbag2Topic& t : found) {
      Rosbag2Topic& b = by_name[t.topic];
      const int64_t before = b.topic.empty() ? 0 : b.messages;
      b = t;
      b.messages = before + std::max<int64_t>(0, t.messages);
    }
  }
  std::vector<Rosbag2Topic> out;
  for (auto& kv : by_name) out.push_back(kv.second);
  return out;
}

const Rosbag2Topic& Rosbag2Reader::topicFor(const std::string& name, const std::string& type,
                                            const std::string& format) {
  Rosbag2Topic& t = known_[name];
  if (t.topic.empty()) t = Rosbag2Topic{name, type, format, -1};
  return t;
}

namespace {
/// A temporary file beside nothing of the user's, removed on destruction.
struct TempFile {
  std::string path;
  explicit TempFile(const std::string& suffix) {
    std::string t = (fs::temp_directory_path() / ("livo-import-XXXXXX" + suffix)).string();
    const int fd = mkstemps(t.data(), static_cast<int>(suffix.size()));
    if (fd < 0) throw Rosbag2Error(t + ": cannot create a temporary file");
    close(fd);
    path = t;
  }
  ~TempFile() { std::remove(path.c_str()); }
  TempFile(const TempFile&) = delete;
  TempFile& operator=(const TempFile&) = delete;
};
}  // namespace

void Rosbag2Reader::readFile(size_t i, const std::function<void(const Rosbag2Message&)>& fn,
                             const std::function<void(double, double)>& progress) {
  const std::string& file = files_.at(i);
  if (!isFile(file)) throw Rosbag2Error(file + ": listed in metadata.yaml but missing");
  std::unique_ptr<TempFile> plain;
  std::string path = file, decompression_error;
  if (compression_mode_ == "FILE") {
    plain = std::make_unique<TempFile>(storage_ == "mcap" ? ".mcap" : ".db3");
    decompression_error = decompressZstdFile(file, plain->path);  // what came out before damage is read
    path = plain->path;
  }
  auto named = [&](const Rosbag2Message& m) {
    if (!plain) return fn(m);
    Rosbag2Message renamed = m;  // errors name the bag's file, not the temporary one
    renamed.where = file + renamed.where.substr(path.size());
    fn(renamed);
  };
  try {
    if (storage_ == "mcap")
      readMcap(path, named, progress);
    else
      readSqlite(path, named, progress);
  } catch (const std::exception& e) {
    std::string what = e.what();
    if (plain && what.rfind(path, 0) == 0) what = file + " (decompressed)" + what.substr(path.size());
    throw Rosbag2Error(decompression_error.empty() ? what : decompression_error + "; then " + what);
  }
  if (!decompression_error.empty()) throw Rosbag2Error(decompression_error);
}

void Rosbag2Reader::deliver(Rosbag2Message& m, const std::function<void(const Rosbag2Message&)>& fn) {
  if (compression_mode_ != "MESSAGE") return fn(m);
  DecompressedChunk plain = decompressZstdFrame(m.data, m.size);
  if (!plain.complete) {
    m.error = plain.error;
    m.data = nullptr;
    m.size = 0;
    return fn(m);
  }
  m.data = plain.data.data();
  m.size = plain.data.size();
  fn(m);
}

void Rosbag2Reader::readMcap(const std::string& file, const std::function<void(const Rosbag2Message&)>& fn,
                             const std::function<void(double, double)>& progress) {
  McapReader reader(file);
  try {
    reader.readAll([&](const McapMessage& m) {
      Rosbag2Message out;
      out.topic = &topicFor(m.channel->topic, m.channel->schema_name, m.channel->message_encoding);
      out.receive_time_ns = static_cast<int64_t>(m.log_time_ns);
      out.data = m.data;
      out.size = m.size;
      out.where = m.where;
      deliver(out, fn);
      if (progress) progress(static_cast<double>(reader.position()), static_cast<double>(reader.fileSize()));
    });
  } catch (const McapError& e) {
    for (const auto& [c, n] : reader.chunkCompressions()) chunk_compressions_[c] += n;
    throw Rosbag2Error(e.what());
  }
  for (const auto& [c, n] : reader.chunkCompressions()) chunk_compressions_[c] += n;
}

void Rosbag2Reader::readSqlite(const std::string& file, const std::function<void(const Rosbag2Message&)>& fn,
                               const std::function<void(double, double)>& progress) {
  Sqlite db(file);
  const std::map<int64_t, Rosbag2Topic> topics = sqliteTopics(db.db, file);
  double total = 0;
  {
    Statement count(db.db, "SELECT COUNT(*) FROM messages", file);
    if (sqlite3_step(count.s) == SQLITE_ROW) total = static_cast<double>(sqlite3_column_int64(count.s, 0));
  }
  Statement st(db.db, "SELECT id, topic_id, timestamp, data FROM messages ORDER BY id", file);
  int rc;
  double done = 0;
  while ((rc = sqlite3_step(st.s)) == SQLITE_ROW) {
    const int64_t id = sqlite3_column_int64(st.s, 0);
    const int64_t topic_id = sqlite3_column_int64(st.s, 1);
    const auto it = topics.find(topic_id);
    if (it == topics.end())
      throw Rosbag2Error(file + ": messages row id " + std::to_string(id) + " refers to topic id " +
                         std::to_string(topic_id) + ", which the topics table lacks");
    Rosbag2Message m;
    m.topic = &topicFor(it->second.topic, it->second.type, it->second.serialization_format);
    m.receive_time_ns = sqlite3_column_int64(st.s, 2);
    m.data = static_cast<const uint8_t*>(sqlite3_column_blob(st.s, 3));
    m.size = static_cast<size_t>(sqlite3_column_bytes(st.s, 3));
    m.where = file + ": messages row id " + std::to_string(id) + " (topic " + it->second.topic + ")";
    deliver(m, fn);
    if (progress) progress(++done, total);
  }
  if (rc != SQLITE_DONE)
    throw Rosbag2Error(file + ": messages table: " + sqlite3_errmsg(db.db) + " after " +
                       std::to_string(static_cast<int64_t>(done)) + " rows");
}

}  // namespace livo::import
