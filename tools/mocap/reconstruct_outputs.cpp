#include "reconstruct_outputs.hpp"

#include <algorithm>
#include <cctype>
#include <charconv>

#include "core/input_error.hpp"

namespace mocap::cli {
namespace {

namespace fs = std::filesystem;

// person_<digits>.bvh
bool is_person_bvh(std::string_view name) {
  constexpr std::string_view prefix = "person_", suffix = ".bvh";
  if (!name.starts_with(prefix) || !name.ends_with(suffix)) return false;
  const std::string_view id =
      name.substr(prefix.size(), name.size() - prefix.size() - suffix.size());
  return !id.empty() && std::all_of(id.begin(), id.end(), [](char c) {
    return std::isdigit(static_cast<unsigned char>(c)) != 0;
  });
}

// Names with their digit runs compared as numbers.
bool natural_less(const std::string& a, const std::string& b) {
  std::size_t i = 0, j = 0;
  while (i < a.size() && j < b.size()) {
    const bool da = std::isdigit(static_cast<unsigned char>(a[i])) != 0;
    const bool db = std::isdigit(static_cast<unsigned char>(b[j])) != 0;
    if (da && db) {
      std::size_t ei = i, ej = j;
      while (ei < a.size() && std::isdigit(static_cast<unsigned char>(a[ei]))) ++ei;
      while (ej < b.size() && std::isdigit(static_cast<unsigned char>(b[ej]))) ++ej;
      const std::string_view na = std::string_view(a).substr(i, ei - i);
      const std::string_view nb = std::string_view(b).substr(j, ej - j);
      if (na.size() != nb.size()) return na.size() < nb.size();
      if (na != nb) return na < nb;
      i = ei, j = ej;
      continue;
    }
    if (a[i] != b[j]) return a[i] < b[j];
    ++i, ++j;
  }
  return a.size() - i < b.size() - j;
}

}  // namespace

bool is_reconstruct_output(std::string_view name) {
  if (name.ends_with(".part")) name.remove_suffix(5);
  return name == "poses.jsonl" || name == "summary.json" || is_person_bvh(name) ||
         name.starts_with("overlay");
}

std::vector<fs::path> reconstruct_outputs_in(const fs::path& folder) {
  std::vector<fs::path> found;
  std::error_code ec;
  if (!fs::exists(folder, ec)) return found;
  for (fs::directory_iterator it(folder, ec), end; !ec && it != end; it.increment(ec)) {
    if (is_reconstruct_output(it->path().filename().string()) && !it->is_directory(ec))
      found.push_back(it->path());
  }
  if (ec) throw InputError(folder.string(), "cannot list the output folder: " + ec.message());
  std::sort(found.begin(), found.end(), [](const fs::path& a, const fs::path& b) {
    return natural_less(a.filename().string(), b.filename().string());
  });
  return found;
}

namespace {

constexpr const char* kAsideFolder = ".mocap-replaced";

void move_file(const fs::path& from, const fs::path& to) {
  std::error_code ec;
  fs::rename(from, to, ec);
  if (ec) throw InputError(from.string(), "cannot move it to " + to.string() + ": " + ec.message());
}

// Moves every file of `from` into `to` and removes `from`.
void move_back(const fs::path& from, const fs::path& to) {
  std::error_code ec;
  for (fs::directory_iterator it(from, ec), end; !ec && it != end; it.increment(ec))
    move_file(it->path(), to / it->path().filename());
  if (ec) throw InputError(from.string(), "cannot list it: " + ec.message());
  fs::remove(from, ec);
}

}  // namespace

EarlierOutput EarlierOutput::prepare(const fs::path& folder, bool force) {
  EarlierOutput earlier;
  earlier.folder_ = folder;
  earlier.aside_ = folder / kAsideFolder;
  std::error_code ec;
  if (fs::exists(folder, ec) && !fs::is_directory(folder, ec))
    throw InputError(folder.string(), "--out names a file, not a folder");
  if (fs::exists(earlier.aside_, ec)) {
    // Left by a --force run that was killed: it replaced these, if it wrote anything.
    if (reconstruct_outputs_in(folder).empty()) {
      move_back(earlier.aside_, folder);
    } else {
      fs::remove_all(earlier.aside_, ec);
      if (ec) throw InputError(earlier.aside_.string(), "cannot remove it: " + ec.message());
    }
  }
  const std::vector<fs::path> found = reconstruct_outputs_in(folder);
  if (!found.empty() && !force) {
    throw InputError(folder.string(),
                     "holds the output of an earlier run (" + describe_outputs(found) +
                         "): give another --out, or add --force to replace it (those files are "
                         "removed once this run has written its first output; other files stay)");
  }
  fs::create_directories(folder, ec);
  if (ec) throw InputError(folder.string(), "cannot create the output folder: " + ec.message());
  if (found.empty()) return earlier;
  fs::create_directory(earlier.aside_, ec);
  if (ec) throw InputError(earlier.aside_.string(), "cannot create it: " + ec.message());
  for (const fs::path& file : found) {
    move_file(file, earlier.aside_ / file.filename());
    earlier.names_.push_back(file.filename());
  }
  return earlier;
}

std::string EarlierOutput::settle(bool run_wrote_output) {
  if (names_.empty()) return {};
  std::vector<fs::path> files;
  for (const fs::path& name : names_) files.push_back(folder_ / name);
  const std::string what =
      std::to_string(names_.size()) + " earlier output file(s) (" + describe_outputs(files) + ")";
  names_.clear();
  if (run_wrote_output) {
    std::error_code ec;
    fs::remove_all(aside_, ec);
    if (ec) throw InputError(aside_.string(), "cannot remove it: " + ec.message());
    return "--force: replaced " + what;
  }
  move_back(aside_, folder_);
  return "the run wrote nothing: " + what + " left as they were";
}

WrittenOutputs classify_outputs(const std::vector<fs::path>& files) {
  WrittenOutputs out;
  for (const fs::path& file : files) {
    const std::string name = file.filename().string();
    if (name.ends_with(".part")) {
      out.partial.push_back(file);
    } else if (name == "poses.jsonl") {
      out.poses.push_back(file);
    } else if (is_person_bvh(name)) {
      int id = -1;
      std::from_chars(name.data() + 7, name.data() + name.size() - 4, id);
      out.bvh.push_back(file);
      out.bvh_ids.push_back(id);
    } else if (name.ends_with(".png") || name.ends_with(".jpg")) {
      out.images.push_back(file);
    } else if (name.starts_with("overlay")) {
      out.videos.push_back(file);
    } else if (name != "summary.json") {
      out.other.push_back(file);
    }
  }
  return out;
}

std::string describe_outputs(const std::vector<fs::path>& files) {
  const WrittenOutputs w = classify_outputs(files);
  std::vector<std::string> parts;
  for (const fs::path& f : w.poses) parts.push_back(f.filename().string());
  for (const fs::path& f : files)
    if (f.filename() == "summary.json") parts.push_back("summary.json");
  if (w.bvh.size() == 1) parts.push_back(w.bvh[0].filename().string());
  if (w.bvh.size() > 1) parts.push_back(std::to_string(w.bvh.size()) + " person_<id>.bvh");
  for (const fs::path& f : w.videos) parts.push_back(f.filename().string());
  if (!w.images.empty()) parts.push_back(std::to_string(w.images.size()) + " overlay image(s)");
  if (!w.partial.empty()) parts.push_back(short_list(w.partial, 2));
  std::string text;
  for (std::size_t i = 0; i < parts.size(); ++i) text += (i ? ", " : "") + parts[i];
  return text;
}

std::string short_list(const std::vector<fs::path>& files, std::size_t show) {
  std::string text;
  for (std::size_t i = 0; i < files.size() && i < show; ++i)
    text += (i ? ", " : "") + files[i].filename().string();
  if (files.size() > show) text += " and " + std::to_string(files.size() - show) + " more";
  return text;
}

}  // namespace mocap::cli
