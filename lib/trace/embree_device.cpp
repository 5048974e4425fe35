#include "trace/embree_device.h"

#include <stdexcept>

namespace qsgi {

EmbreeDevice::EmbreeDevice() {
    // Embree picks its kernels by the CPU, and its SSE/AVX, AVX2 and AVX-512 intersectors round
    // differently (an AVX2 and an SSE4.2 trace of data/cornell differ in some segments' bits):
    // capped at AVX2, every machine with AVX2 (x86 since 2013) traces the same bytes, so that
    // goldens and pinned hashes hold on whatever machine runs them.
    device_ = rtcNewDevice("max_isa=avx2");
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
