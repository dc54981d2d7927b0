// Checkpoint files (Output/Checkpoint Every, capstan run --restart DIR).
//
// A checkpoint of step k is the directory OUTDIR/checkpoint/step-<k>/ with one
// binary file per rank, rank-<r>.bin, written under step-<k>.tmp/ and renamed
// when every rank has written its file: a directory without the .tmp suffix is
// complete. The files hold plain values in the machine's byte order (a
// checkpoint is read back by the same build), each value keyed by global ids
// (node ids; an entity's node ids), so a restart can check that it puts every
// value where it was taken from. The file ends with a checksum of the rest
// (FNV-1a, 64 bits): a damaged file is refused before any value is used.
#pragma once

#include <cstdio>
#include <cstring>
#include <filesystem>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <vector>

namespace capstan::checkpoint {

namespace fs = std::filesystem;

inline const char* kMagic = "capstan checkpoint 8";

inline unsigned long long fnv1a(const char* p, size_t n) {
  unsigned long long h = 14695981039346656037ull;
  for (size_t i = 0; i < n; ++i) h = (h ^ (unsigned char)p[i]) * 1099511628211ull;
  return h;
}

class Writer {
 public:
  template <class T>
  void put(const T& v) {
    static_assert(std::is_trivially_copyable_v<T>);
    buffer_.append(reinterpret_cast<const char*>(&v), sizeof v);
  }
  void put(const std::string& s) {
    put<unsigned long long>(s.size());
    buffer_ += s;
  }
  template <class T>
  void put(const std::vector<T>& v) {
    static_assert(std::is_trivially_copyable_v<T>);
    put<unsigned long long>(v.size());
    buffer_.append(reinterpret_cast<const char*>(v.data()), v.size() * sizeof(T));
  }
  // The file's bytes: the values, then their checksum.
  std::string bytes() const {
    const unsigned long long h = fnv1a(buffer_.data(), buffer_.size());
    return buffer_ + std::string(reinterpret_cast<const char*>(&h), sizeof h);
  }

 private:
  std::string buffer_;
};

// Reads what Writer wrote; throws std::runtime_error on a short or damaged file.
class Reader {
 public:
  explicit Reader(std::string bytes) : buffer_(std::move(bytes)) {
    unsigned long long h;
    if (buffer_.size() < sizeof h) throw std::runtime_error("truncated");
    std::memcpy(&h, buffer_.data() + buffer_.size() - sizeof h, sizeof h);
    buffer_.resize(buffer_.size() - sizeof h);
    if (h != fnv1a(buffer_.data(), buffer_.size())) throw std::runtime_error("damaged (its checksum does not match)");
  }
  template <class T>
  T get() {
    static_assert(std::is_trivially_copyable_v<T>);
    T v;
    std::memcpy(&v, take(sizeof v), sizeof v);
    return v;
  }
  std::string getString() {
    const auto n = get<unsigned long long>();
    return std::string(take(n), n);
  }
  template <class T>
  std::vector<T> getVector() {
    const auto n = get<unsigned long long>();
    if (n > buffer_.size() / sizeof(T)) throw std::runtime_error("damaged (vector length)");
    std::vector<T> v(n);
    if (n) std::memcpy(v.data(), take(n * sizeof(T)), n * sizeof(T));
    return v;
  }
  bool atEnd() const { return pos_ == buffer_.size(); }

 private:
  const char* take(unsigned long long n) {
    if (n > buffer_.size() - pos_) throw std::runtime_error("truncated");
    const char* p = buffer_.data() + pos_;
    pos_ += n;
    return p;
  }
  std::string buffer_;
  size_t pos_ = 0;
};

inline std::string stepName(int step) {
  char name[32];
  std::snprintf(name, sizeof name, "step-%06d", step);
  return name;
}

inline std::string rankFile(int rank) {
  char name[32];
  std::snprintf(name, sizeof name, "rank-%05d.bin", rank);
  return name;
}

// Step number of a complete checkpoint directory name (step-NNNNNN), else -1.
inline int stepOf(const std::string& name) {
  if (name.size() != 11 || name.compare(0, 5, "step-") != 0) return -1;
  int step = 0;
  for (size_t i = 5; i < name.size(); ++i) {
    if (name[i] < '0' || name[i] > '9') return -1;
    step = 10 * step + (name[i] - '0');
  }
  return step;
}

// The complete checkpoint with the highest step under root (OUTDIR/checkpoint),
// or an empty path.
inline fs::path latest(const fs::path& root) {
  std::error_code ec;
  fs::path best;
  int bestStep = -1;
  for (fs::directory_iterator it(root, ec), end; !ec && it != end; it.increment(ec)) {
    const int step = stepOf(it->path().filename().string());
    if (step > bestStep && fs::exists(it->path() / rankFile(0))) {
      bestStep = step;
      best = it->path();
    }
  }
  return best;
}

}  // namespace capstan::checkpoint
