// Fuzz target: pose database files (posedb/database.hpp Database::from_bytes, the checks that
// Database::open runs on a mapped file). Random bytes rarely carry valid CRC-32s, so each input
// is tried twice: as it is with checksums verified, and with the section table's CRC fixed up and
// section checksums off, so the fuzzer reaches the table, section and consistency checks. A
// database that opens is walked through its accessors.

#include <cstring>

#include "core/input_error.hpp"
#include "fuzz_support.hpp"
#include "posedb/database.hpp"
#include "posedb/database_format.hpp"

namespace {

void open_and_walk(std::string bytes, bool verify) {
  using namespace mocap;
  const std::string name = "fuzz-input.mdb";
  try {
    const posedb::Database db = posedb::Database::from_bytes(std::move(bytes), name, verify);
    const auto frames = db.frames();
    for (std::uint32_t f = 0; f < frames.size(); ++f) {
      (void)db.joints(f);
      (void)db.rotations(f);
    }
    for (const auto& r : db.projection_records())
      mocap::fuzz::check(r.frame < frames.size() && r.view < db.views().size(),
                         "a projection record points outside the tables");
    (void)db.options_json();
  } catch (const InputError& e) {
    fuzz::expect_named(e, name);
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace mocap::posedb;
  std::string bytes(mocap::fuzz::text(data, size));
  open_and_walk(bytes, true);
  if (bytes.size() >= sizeof(format::FileHeader)) {
    format::FileHeader h;
    std::memcpy(&h, bytes.data(), sizeof h);
    h.file_size = bytes.size();
    const std::uint64_t table = std::uint64_t{h.section_count} * sizeof(format::SectionEntry);
    if (h.section_count <= 64 && sizeof h + table <= bytes.size())
      h.table_crc = format::crc32_of(bytes.data() + sizeof h, table);
    std::memcpy(bytes.data(), &h, sizeof h);
  }
  open_and_walk(std::move(bytes), false);
  return 0;
}
