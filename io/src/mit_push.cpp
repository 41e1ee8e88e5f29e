// MIT pushing dataset reader (HDF5 C++ API and JSON), with the repairs listed in mit_push.h.
#include <pushgraph/io/mit_push.h>
#include <pushgraph/geometry/types.h>

#include <pushgraph/geometry/json_check.h>
#include <pushgraph/io/trajectory_json.h>  // IoError

#include <H5Cpp.h>
#include <nlohmann/json.hpp>

#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <mutex>
#include <filesystem>
#include <cstdint>
#include <fstream>
#include <iterator>
#include <set>
#include <sstream>

namespace pushgraph::io {
namespace {

using Row = std::array<double, 4>;
struct Raw {
  std::vector<Row> tip, object, ft;
  std::vector<std::string> notes;  // the JSON variant's fields left unread
};
constexpr const char* kDatasets[3] = {"tip_pose", "object_pose", "ft_wrench"};

std::vector<Row>& Slot(Raw& raw, int k) { return k == 0 ? raw.tip : k == 1 ? raw.object : raw.ft; }

// Why HDF5 could not open a file, from its first bytes: not HDF5 at all, or truncated (the
// superblock's end-of-file address beyond the file's size; HDF5 File Format Specification,
// Sec. II.A, superblock versions 0-3, 8-byte offsets), else corrupt.
std::string DescribeUnopenableH5(const std::string& path) {
  if (!std::filesystem::exists(path)) return "no such file";
  std::ifstream in(path, std::ios::binary);
  unsigned char head[48] = {};
  in.read(reinterpret_cast<char*>(head), sizeof head);
  const std::streamsize got = in.gcount();
  std::error_code ec;
  const auto size = std::filesystem::file_size(path, ec);
  if (got < 8 || std::memcmp(head, "\x89HDF\r\n\x1a\n", 8) != 0) {
    return "not an HDF5 file (no HDF5 signature in its first bytes; " + std::to_string(ec ? 0 : size) + " bytes)";
  }
  const int version = head[8];
  const int eof_at = version == 0 ? 40 : version == 1 ? 44 : (version == 2 || version == 3) ? 28 : -1;
  if (eof_at > 0 && got >= eof_at + 8 && !ec) {
    std::uint64_t eof = 0;
    for (int b = 7; b >= 0; --b) eof = (eof << 8) | head[eof_at + b];
    if (eof > size) {
      return "truncated: the file has " + std::to_string(size) + " bytes, its HDF5 superblock says " + std::to_string(eof);
    }
  }
  return "a corrupt HDF5 file (" + std::to_string(ec ? 0 : size) + " bytes; the HDF5 library cannot open it)";
}

Raw ReadH5(const std::string& path) {
  H5::Exception::dontPrint();
  Raw raw;
  std::string stage = "open";
  try {
    H5::H5File file(path, H5F_ACC_RDONLY);
    std::error_code size_ec;
    const double file_bytes = static_cast<double>(std::filesystem::file_size(path, size_ec));
    for (int k = 0; k < 3; ++k) {
      stage = std::string("dataset '") + kDatasets[k] + "'";
      if (!file.nameExists(kDatasets[k])) throw IoError(path + ": missing dataset '" + std::string(kDatasets[k]) + "'");
      if (file.childObjType(kDatasets[k]) != H5O_TYPE_DATASET)
        throw IoError(path + ": '" + kDatasets[k] + "' is a " +
                      (file.childObjType(kDatasets[k]) == H5O_TYPE_GROUP ? "group" : "named type") +
                      ", not an N x 4 dataset of [t, x, y, yaw] (or [t, fx, fy, fz]) rows");
      H5::DataSet ds = file.openDataSet(kDatasets[k]);
      H5::DataSpace space = ds.getSpace();
      hsize_t dims[2] = {0, 0};
      const int rank = space.getSimpleExtentNdims();
      if (rank != 2) throw IoError(path + ": dataset '" + kDatasets[k] + "' must be N x 4, has rank " + std::to_string(rank));
      space.getSimpleExtentDims(dims);
      if (dims[1] != 4)
        throw IoError(path + ": dataset '" + kDatasets[k] + "' must be N x 4, is " + std::to_string(dims[0]) + " x " +
                      std::to_string(dims[1]));
      if (ds.getTypeClass() == H5T_INTEGER)  // read as such, 1461697633.2 s was 1461697633 s and 0.05 m was 0
        throw IoError(path + ": dataset '" + kDatasets[k] + "' holds integers, which cannot carry time stamps to the "
                      "millisecond or positions in metres: the dataset's arrays are 64-bit floats");
      if (ds.getTypeClass() != H5T_FLOAT) throw IoError(path + ": dataset '" + kDatasets[k] + "' is not numeric");
      // A header that claims more rows than the file can hold (corrupt, or a fuzzer's) must not
      // become a huge allocation: even compressed, 8-byte values rarely shrink 64-fold.
      const double claimed_bytes = static_cast<double>(dims[0]) * 4.0 * sizeof(double);
      if (!size_ec && claimed_bytes > 64.0 * file_bytes + 4096.0)
        throw IoError(path + ": dataset '" + kDatasets[k] + "' claims " + std::to_string(dims[0]) +
                      " rows, more than the file's " + std::to_string(static_cast<long long>(file_bytes)) +
                      " bytes can hold (corrupt HDF5)");
      // The same for what the read itself allocates: the element size, and a chunk's size for
      // chunked storage (a 28 KB file claiming a huge chunk made the HDF5 read take 4 GB).
      const size_t element_bytes = ds.getDataType().getSize();
      if (element_bytes == 0 || element_bytes > 16)
        throw IoError(path + ": dataset '" + kDatasets[k] + "' has " + std::to_string(element_bytes) +
                      "-byte elements (corrupt HDF5; expected numbers of at most 16 bytes)");
      const H5::DSetCreatPropList layout = ds.getCreatePlist();
      if (layout.getLayout() == H5D_CHUNKED) {
        hsize_t chunk[2] = {0, 0};
        if (layout.getChunk(2, chunk) != 2 || static_cast<double>(chunk[0]) * static_cast<double>(chunk[1]) *
                                                      static_cast<double>(element_bytes) > 64.0 * file_bytes + 4096.0)
          throw IoError(path + ": dataset '" + kDatasets[k] + "' has chunks of " + std::to_string(chunk[0]) + " x " +
                        std::to_string(chunk[1]) + ", more than the file's " +
                        std::to_string(static_cast<long long>(file_bytes)) + " bytes can hold (corrupt HDF5)");
      }
      std::vector<Row>& rows = Slot(raw, k);
      rows.resize(dims[0]);
      if (dims[0] > 0) ds.read(rows.data(), H5::PredType::NATIVE_DOUBLE);
      // Unix times (1.46e9 s in the dataset) kept in 32-bit floats are 128 s apart: every
      // sample of a push gets one or two time stamps, which no repair can give back.
      if (ds.getTypeClass() == H5T_FLOAT && element_bytes == 4) {
        double largest = 0.0;
        for (const Row& r : rows) largest = std::max(largest, std::abs(r[0]));
        const float f = static_cast<float>(largest);
        const double resolution = static_cast<double>(std::nextafter(f, INFINITY)) - static_cast<double>(f);
        if (resolution > 1e-3) {
          std::ostringstream o;
          o << path << ": dataset '" << kDatasets[k] << "' is stored as 32-bit floats, whose time stamps near "
            << largest << " s are " << resolution << " s apart: the sample times are lost (store them as 64-bit floats)";
          throw IoError(o.str());
        }
      }
    }
  } catch (const H5::Exception& e) {
    if (stage == "open") throw IoError(path + ": cannot open: " + DescribeUnopenableH5(path));
    throw IoError(path + ": cannot read " + stage + " (truncated or corrupt HDF5: " + e.getDetailMsg() + ")");
  }
  return raw;
}

// libhdf5 1.10 can crash on a corrupt file: a recording with the root group's B-tree address
// overwritten by 0xFF bytes (found by fuzz_mit_hdf5) makes H5Lexists copy from a null buffer, and
// the tool died with SIGSEGV. So the file is read by a child process that sends the rows back
// through a pipe; a child that dies becomes a clear error, and HDF5's global state in this
// process is never touched by a corrupt file. One read at a time: HDF5 (serial build) is not
// thread-safe, and a fork while another thread is inside it would copy its half-updated state.
Raw ReadH5InChild(const std::string& path) {
  static std::mutex hdf5_mutex;
  std::lock_guard<std::mutex> lock(hdf5_mutex);
  int fds[2];
  if (pipe(fds) != 0) throw IoError(path + ": cannot read (pipe: " + std::strerror(errno) + ")");
  const pid_t pid = fork();
  if (pid < 0) {
    close(fds[0]);
    close(fds[1]);
    throw IoError(path + ": cannot read (fork: " + std::strerror(errno) + ")");
  }
  auto send = [](int fd, const void* data, std::size_t n) {
    const char* p = static_cast<const char*>(data);
    while (n > 0) {
      const ssize_t w = write(fd, p, n);
      if (w < 0 && errno == EINTR) continue;
      if (w <= 0) return false;
      p += w;
      n -= static_cast<std::size_t>(w);
    }
    return true;
  };
  if (pid == 0) {  // the child: read, send, and leave without running this process's exit handlers
    close(fds[0]);
    std::string error;
    Raw raw;
    try {
      raw = ReadH5(path);
    } catch (const std::exception& e) {
      error = e.what();
    }
    const std::uint64_t failed = error.empty() ? 0 : 1;
    bool ok = send(fds[1], &failed, sizeof failed);
    if (failed) {
      const std::uint64_t n = error.size();
      ok = ok && send(fds[1], &n, sizeof n) && send(fds[1], error.data(), error.size());
    } else {
      for (int k = 0; k < 3 && ok; ++k) {
        const std::vector<Row>& rows = Slot(raw, k);
        const std::uint64_t n = rows.size();
        ok = send(fds[1], &n, sizeof n) && send(fds[1], rows.data(), rows.size() * sizeof(Row));
      }
    }
    close(fds[1]);
    _exit(ok ? 0 : 3);
  }
  close(fds[1]);
  std::string bytes;
  char buffer[65536];
  for (;;) {
    const ssize_t r = read(fds[0], buffer, sizeof buffer);
    if (r < 0 && errno == EINTR) continue;
    if (r <= 0) break;
    bytes.append(buffer, static_cast<std::size_t>(r));
  }
  close(fds[0]);
  int status = 0;
  while (waitpid(pid, &status, 0) < 0 && errno == EINTR) {
  }
  if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) {
    const std::string how = WIFSIGNALED(status) ? "signal " + std::to_string(WTERMSIG(status)) + ", " + strsignal(WTERMSIG(status))
                                                : "exit status " + std::to_string(WEXITSTATUS(status));
    throw IoError(path + ": a corrupt HDF5 file: the HDF5 library crashed reading it (" + how + ")");
  }
  std::size_t at = 0;
  auto take = [&](void* out, std::size_t n) {
    if (bytes.size() - at < n) throw IoError(path + ": cannot read (the HDF5 reader's reply was cut short)");
    if (n == 0) return;  // an empty vector's data() may be null
    std::memcpy(out, bytes.data() + at, n);
    at += n;
  };
  std::uint64_t failed = 0, n = 0;
  take(&failed, sizeof failed);
  if (failed) {
    take(&n, sizeof n);
    std::string error(n, '\0');
    take(error.data(), n);
    throw IoError(error);
  }
  Raw raw;
  for (int k = 0; k < 3; ++k) {
    take(&n, sizeof n);
    if (n > bytes.size() / sizeof(Row)) throw IoError(path + ": cannot read (the HDF5 reader's reply was cut short)");
    std::vector<Row>& rows = Slot(raw, k);
    rows.resize(n);
    take(rows.data(), n * sizeof(Row));
  }
  return raw;
}

Raw ReadJson(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw IoError(path + ": cannot open file");
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  nlohmann::json doc;
  try {
    doc = nlohmann::json::parse(text);
  } catch (const nlohmann::json::exception& e) {
    throw IoError(path + ": malformed JSON: " + geometry::JsonSyntaxErrorText(e.what(), text));
  }
  if (const std::string dup = geometry::FindDuplicateJsonKey(text); !dup.empty()) throw IoError(path + ": " + dup);
  if (!doc.is_object()) throw IoError(path + ": top level must be an object with tip_pose, object_pose, ft_wrench");
  Raw raw;
  // Other fields are left unread, and named: a second tracker's stream under another name must
  // not vanish without a word.
  std::string ignored;
  for (const auto& item : doc.items()) {
    if (std::find(std::begin(kDatasets), std::end(kDatasets), item.key()) == std::end(kDatasets))
      ignored += (ignored.empty() ? "'" : ", '") + item.key() + "'";
  }
  if (!ignored.empty())
    raw.notes.push_back("ignored field(s) " + ignored + ": a recording is read from tip_pose, object_pose and ft_wrench");
  for (int k = 0; k < 3; ++k) {
    if (!doc.contains(kDatasets[k])) throw IoError(path + ": missing field '" + std::string(kDatasets[k]) + "'");
    const nlohmann::json& rows = doc[kDatasets[k]];
    if (!rows.is_array()) throw IoError(path + ": '" + std::string(kDatasets[k]) + "' must be an array of rows");
    for (std::size_t i = 0; i < rows.size(); ++i) {
      const nlohmann::json& r = rows[i];
      const std::string where = path + ": " + kDatasets[k] + "[" + std::to_string(i) + "]";
      if (!r.is_array() || r.size() != 4) throw IoError(where + " must be [t, a, b, c], got " + r.dump());
      Row row;
      for (int c = 0; c < 4; ++c) {
        if (!r[c].is_number()) throw IoError(where + "[" + std::to_string(c) + "] is not a number");
        row[c] = r[c].get<double>();
      }
      Slot(raw, k).push_back(row);
    }
  }
  return raw;
}

// Validates, sorts by time (stable) and drops exact duplicate time stamps.
void Clean(std::vector<Row>* rows, const std::string& path, const char* name, MitRecording* rec) {
  if (rows->size() < 2) throw IoError(path + ": dataset '" + std::string(name) + "' has " + std::to_string(rows->size()) + " samples (need >= 2)");
  for (std::size_t i = 0; i < rows->size(); ++i)
    for (int c = 0; c < 4; ++c)
      if (!std::isfinite((*rows)[i][c]))
        throw IoError(path + ": dataset '" + name + "' row " + std::to_string(i) + " column " + std::to_string(c) + " is not finite");
  int reordered = 0;
  for (std::size_t i = 1; i < rows->size(); ++i) reordered += (*rows)[i][0] < (*rows)[i - 1][0];
  std::stable_sort(rows->begin(), rows->end(), [](const Row& a, const Row& b) { return a[0] < b[0]; });
  const std::size_t before = rows->size();
  // A repeated time stamp keeps its first row; a repeat with other values is counted apart, with
  // the largest difference (it was called a duplicate: a row 3 mm away was dropped as one).
  int conflicting = 0;
  double largest = 0.0;
  for (std::size_t i = 1; i < rows->size(); ++i) {
    const Row& a = (*rows)[i - 1];
    const Row& b = (*rows)[i];
    if (a[0] != b[0] || (a[1] == b[1] && a[2] == b[2] && a[3] == b[3])) continue;
    ++conflicting;
    largest = std::max({largest, std::abs(a[1] - b[1]), std::abs(a[2] - b[2]), std::abs(a[3] - b[3])});
  }
  rows->erase(std::unique(rows->begin(), rows->end(), [](const Row& a, const Row& b) { return a[0] == b[0]; }), rows->end());
  const int dropped = static_cast<int>(before - rows->size());
  rec->samples_reordered += reordered;
  rec->duplicates_dropped += dropped;
  if (rows->size() < 2)  // every time stamp the same (found by fuzz_mit_json: the gap median read past an empty vector)
    throw IoError(path + ": dataset '" + std::string(name) + "' has " + std::to_string(before) + " samples but " +
                  std::to_string(rows->size()) + " distinct time stamp (need >= 2)");
  // Time stamps a corrupted file can hold and the estimator refuses (trajectory_checks.cpp's
  // range and clock-jump rules): refused here, naming the row, not written to a trajectory file
  // (a byte flip's 1.28e168 s was, and a 46-year contact phase reported).
  std::vector<double> gaps;
  for (std::size_t i = 1; i < rows->size(); ++i) gaps.push_back((*rows)[i][0] - (*rows)[i - 1][0]);
  std::nth_element(gaps.begin(), gaps.begin() + gaps.size() / 2, gaps.end());
  const double jump = std::max(push::kClockJumpSeconds, push::kClockJumpPeriods * gaps[gaps.size() / 2]);
  for (std::size_t i = 0; i < rows->size(); ++i) {
    const double t = (*rows)[i][0];
    std::ostringstream where;
    where.precision(12);
    where << path << ": dataset '" << name << "' sample " << i << " (in time order): time " << t;
    if (std::abs(t) > push::kMaxTimeStamp)
      throw IoError(where.str() + " s is out of the supported range (|t| <= 1e11 s): a corrupted time stamp?");
    // Values the estimator refuses, refused here too (a byte flip's x = 7.7e307 m was written to
    // the trajectory file without a word): positions within 1e6 m, forces within 1e9 N.
    const bool wrench = std::string(name) == "ft_wrench";
    const double bound = wrench ? 1e9 : geometry::kMaxCoordinate;
    for (int c = 1; c <= 2; ++c) {
      if (std::abs((*rows)[i][c]) > bound) {
        where << " s: " << (wrench ? (c == 1 ? "fx " : "fy ") : (c == 1 ? "x " : "y ")) << (*rows)[i][c]
              << " is out of the supported range (" << (wrench ? "forces within 1e9 N" : "positions within 1e6 m")
              << "): a corrupted value?";
        throw IoError(where.str());
      }
    }
    if (i > 0 && t - (*rows)[i - 1][0] > jump) {
      where << " s follows " << (*rows)[i - 1][0] << " s: a clock jump of more than max(10 s, 1000 median periods) "
            << "(a corrupted time stamp?)";
      throw IoError(where.str());
    }
  }
  if (reordered > 0) rec->notes.push_back(std::string(name) + ": sorted " + std::to_string(reordered) + " out-of-order samples");
  if (dropped > conflicting)
    rec->notes.push_back(std::string(name) + ": dropped " + std::to_string(dropped - conflicting) + " duplicate samples");
  if (conflicting > 0) {
    std::ostringstream text;
    text << name << ": dropped " << conflicting << " sample" << (conflicting == 1 ? "" : "s")
         << " whose time stamp repeats with other values (the first row of each time kept; the largest difference "
         << largest << " in a column)";
    rec->notes.push_back(text.str());
  }
}

double Wrap(double a) { return std::remainder(a, 2.0 * M_PI); }

void FindContactPhase(MitRecording* rec, const MitReadOptions& o) {
  std::vector<double> times;
  const auto& s = rec->streams;
  if (!rec->force_frozen) {
    for (const auto& f : s.force)
      if (f.force.norm() > o.contact_force) times.push_back(f.t);
    std::ostringstream note;
    note << "contact phase from the force magnitude (> " << o.contact_force << " N)";
    rec->notes.push_back(note.str());
  } else {
    // The object moves only while pushed: its speed over ~20 ms windows.
    const auto& p = s.object_pose;
    for (std::size_t i = 0, j = 0; i < p.size(); ++i) {
      while (j < p.size() && p[j].t < p[i].t + 0.02) ++j;
      if (j >= p.size()) break;
      const double speed = (p[j].pose.translation() - p[i].pose.translation()).norm() / (p[j].t - p[i].t);
      if (speed > o.moving_speed) times.push_back(p[i].t);
    }
    rec->notes.push_back("contact phase from the object's motion (force stream unusable)");
  }
  if (times.empty()) return;
  rec->contact_found = true;
  rec->contact_start = times.front();
  rec->contact_end = times.back();
  if (rec->force_frozen && !s.object_pose.empty()) {
    // Speed over 20 ms windows sees mocap jitter as motion, so a finger that slid past the end
    // of a side kept "pushing" for up to 0.4 s in the rect1 files. The object comes to rest at
    // its final pose when contact ends: the last sample farther from it than rest_tolerance
    // (translation plus 0.05 m times the rotation) ends the contact phase.
    const geometry::Pose2 last = s.object_pose.back().pose;
    double rest_from = rec->contact_start;
    for (const auto& p : s.object_pose) {
      const double away = (p.pose.translation() - last.translation()).norm() + 0.05 * std::abs(Wrap(p.pose.theta - last.theta));
      if (away > o.rest_tolerance) rest_from = p.t;
    }
    if (rest_from < rec->contact_end && rest_from > rec->contact_start) {
      rec->notes.push_back("contact phase ends at " + std::to_string(rest_from - rec->contact_start) +
                           " s, where the object comes to rest (the speed test alone: " +
                           std::to_string(rec->contact_end - rec->contact_start) + " s)");
      rec->contact_end = rest_from;
    }
  }
}

template <typename Sample>
void Trim(std::vector<Sample>* v, double t0, double t1) {
  v->erase(std::remove_if(v->begin(), v->end(), [&](const Sample& s) { return s.t < t0 || s.t > t1; }), v->end());
}

}  // namespace

double MitContactForce(double mass, double mu_surface) {
  const double kDefault = MitReadOptions{}.contact_force;
  constexpr double kMinimum = 0.05;  // N: graph::EstimatorConfig's contact_force_threshold, above a sensor's noise
  if (!(mass > 0.0) || !(mu_surface > 0.0)) return kDefault;
  return std::clamp(0.25 * mu_surface * mass * 9.81, kMinimum, kDefault);
}

MitRecording ReadMitPush(const std::string& path, const MitReadOptions& o) {
  const bool json = path.size() >= 5 && path.compare(path.size() - 5, 5, ".json") == 0;
  Raw raw = json ? ReadJson(path) : ReadH5InChild(path);
  MitRecording rec;
  rec.file = path;
  rec.notes = raw.notes;
  for (int k = 0; k < 3; ++k) Clean(&Slot(raw, k), path, kDatasets[k], &rec);
  // The three sensors record one push: their spans overlap (within the same 10 s).
  for (int a = 0; a < 3; ++a)
    for (int b = 0; b < 3; ++b)
      if (Slot(raw, b).front()[0] - Slot(raw, a).back()[0] > push::kClockJumpSeconds) {
        std::ostringstream o;
        o.precision(12);
        o << path << ": dataset '" << kDatasets[b] << "' starts at " << Slot(raw, b).front()[0] << " s, after '" << kDatasets[a]
          << "' ended at " << Slot(raw, a).back()[0] << " s: the sensors' clocks do not overlap (a corrupted time stamp?)";
        throw IoError(o.str());
      }

  for (const Row& r : raw.tip) rec.streams.finger_pose.push_back({r[0], {r[1], r[2], 0.0}});
  double unwrapped = raw.object.front()[3];
  double largest_yaw = 0.0;
  for (std::size_t i = 0; i < raw.object.size(); ++i) {
    largest_yaw = std::max(largest_yaw, std::abs(raw.object[i][3]));
    if (i > 0) {
      double step = Wrap(raw.object[i][3] - raw.object[i - 1][3]);
      if (std::abs(step) > o.max_yaw_step) {
        const double quarters = std::round(step / (0.5 * M_PI));
        std::ostringstream note;
        note.precision(16);
        if (quarters != 0.0) {
          ++rec.yaw_jumps_repaired;
          note << "object yaw: removed a tracker jump of " << static_cast<int>(quarters) << " x pi/2 at t = " << raw.object[i][0];
        } else {
          note.precision(3);
          note << "object yaw: a step of " << step << " rad (more than max_yaw_step " << o.max_yaw_step
               << ", and no quarter turn) kept at t = ";
          note.precision(16);
          note << raw.object[i][0];
        }
        rec.notes.push_back(note.str());
        step -= quarters * 0.5 * M_PI;
      }
      unwrapped += step;
    }
    rec.streams.object_pose.push_back({raw.object[i][0], {raw.object[i][1], raw.object[i][2], unwrapped}});
  }
  // The dataset's tracker reports yaw in (-pi, pi]; beyond a turn it is most likely in degrees.
  if (largest_yaw > 2.0 * M_PI) {
    std::ostringstream note;
    note.precision(4);
    note << "object yaw reaches " << largest_yaw << ", more than a turn in radians (the dataset's yaw lies in -pi to pi): "
         << "is it in degrees? (read as radians)";
    rec.notes.push_back(note.str());
  }

  // A frozen sensor repeats a handful of values (the rect1 recordings: 2 to 4, with spikes).
  std::set<std::pair<double, double>> distinct;
  std::size_t longest_run = 1, run = 1;
  for (std::size_t i = 0; i < raw.ft.size(); ++i) {
    distinct.insert({raw.ft[i][1], raw.ft[i][2]});
    run = (i > 0 && raw.ft[i][1] == raw.ft[i - 1][1] && raw.ft[i][2] == raw.ft[i - 1][2]) ? run + 1 : 1;
    longest_run = std::max(longest_run, run);
  }
  if (raw.ft.size() > 20 && (static_cast<int>(distinct.size()) <= o.frozen_max_distinct || longest_run * 2 > raw.ft.size())) {
    rec.force_frozen = true;
    std::ostringstream why;
    why << "force sensor frozen: " << distinct.size() << " distinct values in " << raw.ft.size()
        << " samples, longest constant run " << longest_run << "; force stream not used";
    rec.force_fault = why.str();
    rec.notes.push_back(rec.force_fault);
  } else {
    for (const Row& r : raw.ft) rec.streams.force.push_back({r[0], {-r[1], -r[2]}});  // on the object = -(on the sensor)
  }

  FindContactPhase(&rec, o);
  if (o.trim_to_contact && rec.contact_found) {
    const std::size_t objects = rec.streams.object_pose.size(), fingers = rec.streams.finger_pose.size();
    Trim(&rec.streams.object_pose, rec.contact_start, rec.contact_end);
    Trim(&rec.streams.finger_pose, rec.contact_start, rec.contact_end);
    Trim(&rec.streams.force, rec.contact_start, rec.contact_end);
    // A contact phase that holds no pose: the force sensor's clock offset from the trackers' (one
    // shifted by a second was written with 0 object and 0 finger samples, exit 0, and `estimate`
    // then said "nothing anchors the object").
    const bool no_object = rec.streams.object_pose.empty() && objects > 0, no_finger = rec.streams.finger_pose.empty() && fingers > 0;
    if (no_object || no_finger) {
      std::ostringstream text;
      text.precision(12);
      text << path << ": the contact phase (" << (rec.force_frozen ? "from the object's motion" : "from the force magnitude")
           << ", " << rec.contact_start << " to " << rec.contact_end
           << " s) holds no " << (no_object && no_finger ? "object or finger pose" : no_object ? "object pose" : "finger pose")
           << " sample, though the recording has " << (no_object ? objects : fingers) << " (from "
           << (no_object ? raw.object : raw.tip).front()[0] << " to " << (no_object ? raw.object : raw.tip).back()[0]
           << " s): are the force sensor's and the trackers' clocks offset? mit-import --no-trim keeps every sample";
      throw IoError(text.str());
    }
  }
  return rec;
}

push::Trajectory MitToTrajectory(const MitRecording& rec, const push::ObjectDescription& object,
                                          const push::FingerDescription& finger) {
  push::Trajectory t;
  t.object = object;
  t.finger = finger;
  t.measured = rec.streams;
  t.ground_truth = rec.streams;
  return t;
}

}  // namespace pushgraph::io
