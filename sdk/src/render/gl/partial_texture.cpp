#include "partial_texture.hpp"

#include "context_check.hpp"

namespace splatfx::gl::detail {

PartialTexture::~PartialTexture() {
    if (mTexture && contextIsCurrent()) glDeleteTextures(1, &mTexture);
}

void PartialTexture::update(const Footprint& fp) {
    const int rows = fp.partialRows(), cols = fp.partialCols();
    if (mTexture && rows == mRows && cols == mCols && fp.partialTable() == mUploaded) return;
    if (mTexture) glDeleteTextures(1, &mTexture);
    glCreateTextures(GL_TEXTURE_2D, 1, &mTexture);
    // R32F: the fractions near 0 and 1 need more than half precision's 11 bits.
    glTextureStorage2D(mTexture, 1, GL_R32F, cols, rows);
    glTextureSubImage2D(mTexture, 0, 0, 0, cols, rows, GL_RED, GL_FLOAT, fp.partialTable().data());
    glTextureParameteri(mTexture, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
    glTextureParameteri(mTexture, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
    glTextureParameteri(mTexture, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
    glTextureParameteri(mTexture, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
    mRows = rows;
    mCols = cols;
    mUploaded = fp.partialTable();
}

} // namespace splatfx::gl::detail
