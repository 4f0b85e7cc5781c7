#pragma once
// Who the VMC live link sends (sink.vmc): one person chosen per frame (the first still in view,
// the largest in the image, or a fixed id), or everybody, each on their own UDP port. The node
// only reads its parameters and calls these; the state that lives across frames is here.

#include <cstdint>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "core/messages.hpp"
#include "export/vmc_sender.hpp"

namespace mocap::exporting {

// One person per frame. "first": the current person while they are in view, else the one seen
// earliest (ties: the smaller id); "largest": the biggest in the image (the extent of the
// detected keypoints, else of the 3D body); a number: that id only.
class VmcPersonChoice {
 public:
  // Throws std::invalid_argument when `rule` is none of first, largest or a whole number.
  explicit VmcPersonChoice(const std::string& rule);
  const Person3D* choose(const People3D& people);

 private:
  const Person3D* first(const People3D& people);

  bool largest_ = false;
  std::optional<int> fixed_id_;
  int current_ = -1;
  std::map<int, std::int64_t> first_seen_;  // id -> first frame
};

// Everybody, person i on port + slot: a person keeps their port while they are seen; a new person
// takes a port never used or, when all max_people are taken, the one whose person has been away
// for release_s or longer; none when every port is busy.
class VmcPorts {
 public:
  VmcPorts(std::string host, int port, int max_people, double release_s);
  VmcSender* sender_for(int id, double t);
  VmcSender& first_port();  // port itself (the single-person link)
  int ports_open() const { return static_cast<int>(senders_.size()); }

  struct Totals {
    std::uint64_t bundles = 0, messages = 0, failures = 0;
  };
  Totals totals() const;

 private:
  VmcSender& sender_at(int slot);

  std::string host_;
  int port_ = kVmcDefaultPort, max_people_ = 8;
  double release_s_ = 1.0;
  struct Slot {
    int port = 0;  // offset from port_
    double last_seen = 0.0;
  };
  std::map<int, Slot> slots_;  // id -> its port
  std::vector<std::unique_ptr<VmcSender>> senders_;
};

// Seconds since the first message: from capture times when the messages carry them, else from
// frame numbers at `fps`.
class VmcClock {
 public:
  explicit VmcClock(double fps) : fps_(fps) {}
  double seconds(const Header& h);

 private:
  double fps_;
  bool started_ = false;
  std::int64_t first_ns_ = 0, first_frame_ = 0;
};

}  // namespace mocap::exporting
