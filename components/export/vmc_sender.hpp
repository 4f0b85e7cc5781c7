#pragma once
// The VMC protocol's performer side (Virtual Motion Capture Protocol, protocol.vmc.info): OSC over
// UDP, one bundle per frame with
//   /VMC/Ext/OK 1                        (the avatar is loaded)
//   /VMC/Ext/T <time s>                  (float)
//   /VMC/Ext/Root/Pos "root" px py pz qx qy qz qw
//   /VMC/Ext/Bone/Pos <HumanBodyBones name> px py pz qx qy qz qw   (one per humanoid bone)
// in Unity's coordinates (export/humanoid.hpp). Sent with liblo; its headers stay in the .cpp.
// docs/live-link.md says how to receive it.

#include <cstdint>
#include <memory>
#include <string>

#include "export/humanoid.hpp"

namespace mocap::exporting {

inline constexpr int kVmcDefaultPort = 39539;  // the port VMC receivers listen on by default

class VmcSender {
 public:
  // Resolves host:port; throws InputError naming "host:port" when it cannot.
  VmcSender(const std::string& host, int port);
  ~VmcSender();
  VmcSender(const VmcSender&) = delete;
  VmcSender& operator=(const VmcSender&) = delete;

  // Sends one frame as one bundle (2 + 1 + kHumanBones messages). A failed send (no route, a
  // full socket buffer) is counted, not thrown: a live link drops frames rather than stopping.
  void send(const HumanoidPose& pose, double time_s);

  std::uint64_t bundles_sent() const { return bundles_; }
  std::uint64_t messages_sent() const { return messages_; }
  std::uint64_t send_failures() const { return failures_; }
  const std::string& target() const { return target_; }

 private:
  struct Address;
  std::unique_ptr<Address> address_;
  std::string target_;
  std::uint64_t bundles_ = 0, messages_ = 0, failures_ = 0;
};

}  // namespace mocap::exporting
