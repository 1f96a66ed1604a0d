// Materials registers texture sets and colour tables once per distinct
// content, and presets share them (issue 12).
#include <string>

#include <gtest/gtest.h>

#include "splatfx/materials.hpp"
#include "splatfx/presets.hpp"
#include "splatfx/texture_set_io.hpp"

using namespace splatfx;

namespace {

// A small set whose content is fixed by `tag` (distinct tags, distinct texels).
TextureSet taggedSet(int count, int tag) {
    TextureSet s;
    s.size = 8;
    for (int i = 0; i < count; ++i) {
        std::vector<float> px(8 * 8 * 4, 1.0f);
        for (size_t t = 3; t < px.size(); t += 4) px[t] = float((t / 4 + size_t(i) * 7 + size_t(tag) * 13) % 17) / 16.0f;
        s.layers.push_back(std::move(px));
    }
    return s;
}

} // namespace

TEST(Materials, EqualTextureSetsAreRegisteredOnce) {
    Materials m{Footprint{}};
    const auto a = m.addTextureSet(TextureSet::turbulence({.count = 4, .seed = 7}));
    const std::uint32_t layers = m.layerCount();
    const std::uint64_t version = m.version();
    const auto again = m.addTextureSet(TextureSet::turbulence({.count = 4, .seed = 7}));
    EXPECT_EQ(again, a);
    EXPECT_EQ(m.layerCount(), layers); // nothing added ...
    EXPECT_EQ(m.version(), version);   // ... so renderers need not re-upload
    const auto b = m.addTextureSet(TextureSet::turbulence({.count = 4, .seed = 8}));
    EXPECT_NE(b, a);
    EXPECT_EQ(m.layerCount(), layers + 4);
    // Ids stay as they were: the first set still starts where it did.
    EXPECT_EQ(m.set(a).first, 1u);
    EXPECT_EQ(m.set(b).first, 5u);
    EXPECT_EQ(m.setCount(), 2u);
}

TEST(Materials, SetsThatDifferOnlyInTheirColourFlagAreDistinct) {
    Materials m{Footprint{}};
    TextureSet gray = TextureSet::turbulence({.count = 2, .size = 16, .seed = 3});
    TextureSet colour = gray;
    colour.color = true;
    EXPECT_NE(m.addTextureSet(gray), m.addTextureSet(colour));
}

TEST(Materials, KeysFindSetsAndRefuseOtherContent) {
    Materials m{Footprint{}};
    EXPECT_FALSE(m.findTextureSet("mine"));
    auto id = m.addTextureSet(taggedSet(3, 1), "mine");
    ASSERT_TRUE(id) << id.error();
    ASSERT_TRUE(m.findTextureSet("mine"));
    EXPECT_EQ(*m.findTextureSet("mine"), *id);
    EXPECT_EQ(m.setKey(*id), "mine");
    // Same key, same content: the same id.
    auto same = m.addTextureSet(taggedSet(3, 1), "mine");
    ASSERT_TRUE(same);
    EXPECT_EQ(*same, *id);
    // Same key, other content: an error naming the key; nothing added.
    const std::uint32_t layers = m.layerCount();
    auto clash = m.addTextureSet(taggedSet(3, 2), "mine");
    ASSERT_FALSE(clash);
    EXPECT_NE(clash.error().find("'mine'"), std::string::npos) << clash.error();
    EXPECT_EQ(m.layerCount(), layers);
    // A second key for registered content is an alias, not a copy.
    auto alias = m.addTextureSet(taggedSet(3, 1), "also mine");
    ASSERT_TRUE(alias);
    EXPECT_EQ(*alias, *id);
    EXPECT_EQ(m.layerCount(), layers);
    EXPECT_EQ(m.setKey(*id), "mine"); // named by its first key
    // Unkeyed content equal to a keyed set shares it too.
    EXPECT_EQ(m.addTextureSet(taggedSet(3, 1)), *id);
    EXPECT_FALSE(m.addTextureSet(taggedSet(3, 1), ""));
}

TEST(Materials, EqualColourTablesAreRegisteredOnce) {
    Materials m{Footprint{}};
    const auto fire = m.addColorTable(ColorTable::fire());
    EXPECT_EQ(m.addColorTable(ColorTable::fire()), fire);
    const auto smoke = m.addColorTable(ColorTable::smoke());
    EXPECT_NE(smoke, fire);
    EXPECT_EQ(m.colorTableCount(), 2u);
    auto keyed = m.addColorTable(ColorTable::smoke(), "smoke");
    ASSERT_TRUE(keyed);
    EXPECT_EQ(*keyed, smoke);
    EXPECT_EQ(m.colorTableKey(smoke), "smoke");
    EXPECT_FALSE(m.addColorTable(ColorTable::fire(), "smoke"));
    EXPECT_EQ(m.colorTableCount(), 2u);
}

TEST(Materials, LayerLimitErrorNamesTheLargestSetsAndWhatToDo) {
    Materials m{Footprint{}, {.layerSize = 8}};
    ASSERT_TRUE(m.addTextureSet(taggedSet(2, 1), "small"));
    ASSERT_TRUE(m.addTextureSet(taggedSet(12, 2), "big"));
    m.addTextureSet(taggedSet(5, 3)); // unkeyed: named by id
    EXPECT_EQ(m.layerCount(), 1u + 2u + 12u + 5u);
    EXPECT_TRUE(m.checkLayerLimit(m.layerCount()));
    const Status s = m.checkLayerLimit(m.layerCount() - 1);
    ASSERT_FALSE(s);
    const std::string& e = s.error();
    EXPECT_NE(e.find("20 texture layers"), std::string::npos) << e;
    EXPECT_NE(e.find("allows 19"), std::string::npos) << e;
    EXPECT_NE(e.find("set 1 ('big') 12 layers"), std::string::npos) << e;
    EXPECT_NE(e.find("set 2 (unkeyed) 5 layers"), std::string::npos) << e;
    EXPECT_NE(e.find("set 0 ('small') 2 layers"), std::string::npos) << e;
    EXPECT_LT(e.find("'big'"), e.find("'small'")) << "largest first: " << e;
    EXPECT_NE(e.find("textureSeed"), std::string::npos) << e; // says what to do
}

TEST(Presets, EffectsWithDifferentSeedsShareTheirTextureSets) {
    Materials m{Footprint{}};
    auto a = presets::fire(m, {.seed = 1});
    auto b = presets::fire(m, {.seed = 2});
    ASSERT_TRUE(a && b);
    EXPECT_EQ(a->layer(0).style.textureSet, b->layer(0).style.textureSet);
    EXPECT_EQ(a->layer(0).style.colorTable, b->layer(0).style.colorTable);
    EXPECT_EQ(m.setCount(), 1u);
    // `seed` still tells the two apart: it drives the texture dynamics.
    EXPECT_NE(a->desc().textures.seed, b->desc().textures.seed);
    // The set is the one TextureSet::turbulence makes for those parameters.
    Materials direct{Footprint{}};
    const auto d = direct.addTextureSet(TextureSet::turbulence({.count = 8, .size = 32, .seed = 1, .contrast = 2.5f}));
    for (std::uint32_t i = 0; i < 8; ++i)
        EXPECT_EQ(m.layer(m.set(a->layer(0).style.textureSet).first + i), direct.layer(direct.set(d).first + i)) << "layer " << i;
    // A different textureSeed is different content: one more set.
    auto c = presets::fire(m, {.seed = 3, .textureSeed = 9});
    ASSERT_TRUE(c);
    EXPECT_NE(c->layer(0).style.textureSet, a->layer(0).style.textureSet);
    EXPECT_EQ(m.setCount(), 2u);
}

TEST(Presets, AGivenSetIsSharedByContent) {
    auto folder = loadTextureSet(std::string(SPLATFX_SOURCE_DIR "/textures/turbulence-8x32"));
    ASSERT_TRUE(folder) << folder.error();
    auto again = loadTextureSet(std::string(SPLATFX_SOURCE_DIR "/textures/turbulence-8x32/")); // spelled differently
    ASSERT_TRUE(again) << again.error();
    Materials m{Footprint{}};
    auto a = presets::steam(m, {.textureSet = *folder});
    auto b = presets::steam(m, {.textureSet = *again, .seed = 5});
    ASSERT_TRUE(a) << a.error();
    ASSERT_TRUE(b) << b.error();
    EXPECT_EQ(a->layer(0).style.textureSet, b->layer(0).style.textureSet);
    EXPECT_EQ(m.setCount(), 1u);
}

TEST(Presets, AFailedPresetRegistersNothing) {
    Materials m{Footprint{}};
    auto bad = presets::fireToSmoke(m, {.smokeTextureSet = TextureSet{}}); // an empty set: refused after the fire set was built
    ASSERT_FALSE(bad);
    EXPECT_NE(bad.error().find("smokeTextureSet"), std::string::npos) << bad.error();
    EXPECT_EQ(m.setCount(), 0u);
    EXPECT_EQ(m.layerCount(), 1u);
}
