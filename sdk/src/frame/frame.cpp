#include "splatfx/frame.hpp"

namespace splatfx {

void Frame::begin(double timeSec, const Camera& camera) {
    mTime = timeSec;
    mCounters = {};
    mBuilder.begin(camera);
    mVolumes.clear(); // [clouds]
    mEmittedLights.clear();
    mEmittedGrid = {};
}

void Frame::end(SortMode mode) {
    mBuilder.sort(mode);
    mCounters.splats = mBuilder.splats().size();
    mCounters.voxels = mBuilder.stats().voxelsIn;
    interleaveBackToFront(mBuilder.splats(), mVolumes, mBuilder.camera(), mDrawOrder); // [clouds]
}

} // namespace splatfx
