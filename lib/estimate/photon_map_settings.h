// The photon map's own parameters (docs/design.md §5; the algorithm is photon_map.h). A light
// header: the option table sets these fields directly.
#pragma once

namespace qsgi {

struct PhotonMapSettings {
    int k = 50;  // neighbours: the nearest impacts per vertex
};

}  // namespace qsgi
