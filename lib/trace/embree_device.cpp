#include "trace/embree_device.h"

#include <stdexcept>

namespace qsgi {

EmbreeDevice::EmbreeDevice() {
    device_ = rtcNewDevice(nullptr);
    if (!device_) throw std::runtime_error("Embree: cannot create a device (error " + std::to_string(rtcGetDeviceError(nullptr)) + ")");
}

EmbreeDevice::~EmbreeDevice() { rtcReleaseDevice(device_); }

void EmbreeDevice::checkError(const char* during) const {
    const RTCError e = rtcGetDeviceError(device_);
    if (e != RTC_ERROR_NONE) throw std::runtime_error(std::string("Embree error ") + std::to_string(int(e)) + " during " + during);
}

EmbreeScene::EmbreeScene(const EmbreeDevice& device) {
    scene_ = rtcNewScene(device.get());
    device.checkError("rtcNewScene");
}

EmbreeScene::~EmbreeScene() { rtcReleaseScene(scene_); }

}  // namespace qsgi
