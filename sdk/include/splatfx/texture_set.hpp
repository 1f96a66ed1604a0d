// splatfx/texture_set.hpp: the detail textures drawn inside the splats.
//
// King et al. 1999, sec. 2 step 1: a small set of textures holding the
// frequencies to model, converted to grayscale and windowed by the footprint
// (Figure 2), so each textured splat carries detail yet fades out like a
// footprint. Sets come from Perlin turbulence (deterministic per seed, no
// files needed) or from a texture-set folder (e.g. made by splatfx-texpick).
// It does not upload anything: the GL renderer does.
// Reading and writing texture-set folders is splatfx::io:
// loadTextureSet / saveTextureSet in splatfx/texture_set_io.hpp.
//
//   auto raw = splatfx::TextureSet::turbulence({.count = 8, .size = 32, .seed = 7});
//   auto splats = raw.windowed(splatfx::Footprint{});
//
// Texture-set folder: manifest.json {"format": "splatfx-texture-set",
// "version": 1, "textures": ["t00.png", ...], "color": false, ...} plus the
// images (all the same square size). Unknown keys are kept for provenance.
//
// Threading: a plain value.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "splatfx/footprint.hpp"
#include "splatfx/image.hpp"
#include "splatfx/result.hpp"

namespace splatfx {

struct TurbulenceDesc {
    int count = 8;              // textures in the set; default 8 (the paper's choice)
    int size = 32;              // texels on a side; default 32 (sec. 5.4)
    std::uint32_t seed = 1;     // default 1
    int octaves = 4;            // turbulence octaves; default 4
    float baseFrequency = 3.0f; // lowest octave, cycles per texture; default 3
    // Textures are slices along a closed loop through 4D noise, so cycling
    // them in order is smooth and periodic (sec. 3.3 "cyclical pattern").
    float loopRadius = 0.25f; // noise units; larger = faster change between textures; default 0.25
    // Exponent applied after normalization: above 1 the detail gets sparser
    // and sharper, which survives the averaging of many overlapping splats
    // (fire: 2.5). Default 1 (plain turbulence).
    float contrast = 1.0f;
};

// Windows cut from one larger image (King et al. 1999, sec. 4 / Fig. 11:
// textures taken at random positions from a photograph).
struct ImageSampleDesc {
    int count = 16;                       // windows cut, >= 1; default 16
    int size = 32;                        // window side in pixels (the set's texture size), >= 1; default 32
    std::uint32_t seed = 1;               // picks the window positions; default 1
    bool keepColor = false;               // keep RGB detail (else grayscale); default false
    std::string sourceName = "the image"; // names the image in messages (e.g. "image 'wood.jpg'"); default "the image"
};

class TextureSet {
public:
    int size = 0;       // texels on a side (square)
    bool color = false; // true: RGB detail kept; false: grayscale (R=G=B=1, detail in A)
    bool isWindowed = false;
    // One RGBA float image per texture, size x size, row-major.
    std::vector<std::vector<float>> layers;

    int count() const { return static_cast<int>(layers.size()); }

    // Perlin turbulence (sum of |noise| octaves), normalized to [0, 1].
    static TextureSet turbulence(const TurbulenceDesc& desc);
    // One texture per image file; all must be square and the same size.
    static Result<TextureSet> fromImages(const std::vector<Image>& images, bool keepColor);
    // desc.count square windows of desc.size pixels at seeded positions
    // inside `source` (each window lies wholly inside it), as fromImages
    // makes them. Fails when the image is smaller than a window (the message
    // names it with desc.sourceName), when its pixels do not match its size,
    // or as fromImages fails. Pure: reading the file is the caller's part.
    static Result<TextureSet> sampleImage(const Image& source, const ImageSampleDesc& desc);

    // Figure 2: grayscale (unless color), contrast kept, multiplied by the
    // footprint weight over the texture's extent. Opacity detail ends up in A.
    TextureSet windowed(const Footprint& footprint) const;
    // Box-filters or bilinearly resamples every layer to newSize.
    TextureSet resized(int newSize) const;
    // The plain footprint as a one-layer set: traditional splatting (Fig. 1a).
    static TextureSet footprintOnly(const Footprint& footprint, int size);
};

} // namespace splatfx
