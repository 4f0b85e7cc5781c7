#include "export/vmc_sender.hpp"

#include <lo/lo.h>

#include "core/input_error.hpp"

namespace mocap::exporting {

struct VmcSender::Address {
  lo_address address = nullptr;
  ~Address() {
    if (address) lo_address_free(address);
  }
};

VmcSender::VmcSender(const std::string& host, int port)
    : address_(std::make_unique<Address>()), target_(host + ":" + std::to_string(port)) {
  if (port < 1 || port > 65535) throw InputError(target_, "the UDP port must be 1-65535");
  address_->address = lo_address_new(host.c_str(), std::to_string(port).c_str());
  if (!address_->address) throw InputError(target_, "cannot make an OSC address of it");
}

VmcSender::~VmcSender() = default;

namespace {

// Adds "path name px py pz qx qy qz qw" to the bundle (which then owns the message).
void add_transform(lo_bundle bundle, const char* path, const char* name, const glm::vec3& p,
                   const glm::quat& q) {
  lo_message m = lo_message_new();
  lo_message_add_string(m, name);
  for (float v : {p.x, p.y, p.z, q.x, q.y, q.z, q.w}) lo_message_add_float(m, v);
  lo_bundle_add_message(bundle, path, m);
}

}  // namespace

void VmcSender::send(const HumanoidPose& pose, double time_s) {
  // lo_bundle_free_recursive frees the bundle and every message added to it.
  std::unique_ptr<std::remove_pointer_t<lo_bundle>, void (*)(lo_bundle)> bundle(
      lo_bundle_new(LO_TT_IMMEDIATE), lo_bundle_free_recursive);
  if (!bundle) {
    ++failures_;
    return;
  }
  lo_message ok = lo_message_new();
  lo_message_add_int32(ok, 1);
  lo_bundle_add_message(bundle.get(), "/VMC/Ext/OK", ok);
  lo_message t = lo_message_new();
  lo_message_add_float(t, static_cast<float>(time_s));
  lo_bundle_add_message(bundle.get(), "/VMC/Ext/T", t);
  add_transform(bundle.get(), "/VMC/Ext/Root/Pos", "root", pose.root_position, pose.root_rotation);
  for (int b = 0; b < kHumanBones; ++b) {
    add_transform(bundle.get(), "/VMC/Ext/Bone/Pos", std::string(kHumanBoneNames[b]).c_str(),
                  pose.position[b], pose.rotation[b]);
  }
  if (lo_send_bundle(address_->address, bundle.get()) < 0) {
    ++failures_;
    return;
  }
  ++bundles_;
  messages_ += 3 + kHumanBones;
}

}  // namespace mocap::exporting
