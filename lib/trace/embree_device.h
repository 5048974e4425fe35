// RAII ownership of an Embree device; Embree errors become exceptions with Embree's message.
#pragma once

#include <embree3/rtcore.h>

#include <string>

namespace qsgi {

class EmbreeDevice {
public:
    EmbreeDevice();
    ~EmbreeDevice();
    EmbreeDevice(const EmbreeDevice&) = delete;
    EmbreeDevice& operator=(const EmbreeDevice&) = delete;

    RTCDevice get() const { return device_; }
    // Throws std::runtime_error if Embree reported an error since the last check.
    void checkError(const char* during) const;

private:
    RTCDevice device_ = nullptr;
};

// RAII ownership of one Embree scene.
class EmbreeScene {
public:
    explicit EmbreeScene(const EmbreeDevice& device);
    ~EmbreeScene();
    EmbreeScene(const EmbreeScene&) = delete;
    EmbreeScene& operator=(const EmbreeScene&) = delete;
    RTCScene get() const { return scene_; }

private:
    RTCScene scene_ = nullptr;
};

}  // namespace qsgi
