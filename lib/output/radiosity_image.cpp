#include "output/radiosity_image.h"

#include <tbb/blocked_range2d.h>
#include <tbb/parallel_for.h>

#include <cmath>
#include <limits>

#include "scene/surface_lookup.h"
#include "trace/counter_rng.h"
#include "trace/sampling.h"

namespace qsgi {

RgbImage renderRadiosityImage(const Scene& scene, const SceneBvh& bvh, const VertexRadiosity& solution,
                              const Camera& camera, const ImageSettings& settings) {
    RgbImage image;
    image.width = settings.width;
    image.height = settings.height;
    image.pixels.assign(size_t(settings.width) * size_t(settings.height) * 3, 0.0f);
    const int spp = std::max(1, settings.samplesPerPixel);
    const float tnear = std::max(camera.znear, 0.0f);
    // Where the albedo varies over a triangle the pixel shows the texel's albedo times the
    // interpolated irradiance (plus the emission), as the artist's engine shows the bake on the
    // textured asset; elsewhere B interpolated, which is the same.
    const SurfaceLookup& surfaces = bvh.surfaces();
    // B/π of the surface at a hit.
    auto shade = [&](const SurfaceHit& hit) {
        const Triangle& t = scene.triangles[hit.triangle];
        if (surfaces.varies(hit.triangle)) {
            const Vec3f e = solution.irradiance[t.v[0]] * (1 - hit.u - hit.v) + solution.irradiance[t.v[1]] * hit.u +
                            solution.irradiance[t.v[2]] * hit.v;
            const float reflected = surfaces.reflectedShare(hit.triangle, hit.u, hit.v);
            return surfaces.albedo(hit.triangle, hit.u, hit.v) * (e * reflected) +
                   surfaces.emission(hit.triangle, hit.u, hit.v) * float(M_PI);
        }
        return solution.radiosity[t.v[0]] * (1 - hit.u - hit.v) + solution.radiosity[t.v[1]] * hit.u +
               solution.radiosity[t.v[2]] * hit.v;
    };
    // Each pixel depends only on its own rays, so tiles can run in any order.
    tbb::parallel_for(tbb::blocked_range2d<int>(0, settings.height, 16, 0, settings.width, 16),
                      [&](const tbb::blocked_range2d<int>& tile) {
        for (int y = tile.rows().begin(); y != tile.rows().end(); ++y)
            for (int x = tile.cols().begin(); x != tile.cols().end(); ++x) {
                const uint64_t pixel = uint64_t(y) * uint64_t(settings.width) + uint64_t(x);
                const PhotonRandom jitter(settings.seed ^ 0x5EED1AA6Eull, pixel);
                Vec3d sum(0.0);
                for (int s = 0; s < spp; ++s) {
                    const float jx = spp == 1 ? 0.5f : jitter.uniform(uint32_t(s), 0);
                    const float jy = spp == 1 ? 0.5f : jitter.uniform(uint32_t(s), 1);
                    const CameraRay ray = cameraRay(camera, float(x) + jx, float(y) + jy, settings.width, settings.height);
                    // A BLEND surface is composited over what lies behind it by its alpha (its
                    // B already holds its alpha share); anything else ends the ray.
                    float from = tnear, behind = 1;
                    for (int layer = 0; layer <= SceneBvh::kMostPanes; ++layer) {
                        const auto hit = bvh.closestHit(ray.origin, ray.direction, from, std::numeric_limits<float>::infinity(), true);
                        if (!hit) break;
                        sum += Vec3d(shade(*hit) * behind);
                        if (!surfaces.blends(hit->triangle)) break;
                        behind *= 1 - surfaces.baseColour(hit->triangle, hit->u, hit->v)[3];
                        if (!(behind > 0)) break;
                        from = std::nextafter(hit->t, std::numeric_limits<float>::infinity());
                    }
                }
                const Vec3f radiance = Vec3f(sum / (double(spp) * M_PI));
                float* out = &image.pixels[pixel * 3];
                out[0] = radiance.x;
                out[1] = radiance.y;
                out[2] = radiance.z;
            }
    });
    return image;
}

}  // namespace qsgi
