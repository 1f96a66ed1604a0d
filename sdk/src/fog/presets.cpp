// The example fogs of Biri, Michelin & Arques 2002, sec. 6.
#include <numbers>

#include "splatfx/fog.hpp"

namespace splatfx {

FogDesc paperFig6Fog() {
    // K_t(x, y, z) = 1 + 1/2 cos(5 pi y) + 1/5 cos(7 pi (y + 0.1 x)) + 1/5 cos(5 pi (y - 0.05 x))
    //              + 1/10 cos(pi x) cos(pi z / 2)          (the formula under Fig. 6)
    // The constant equals the sum of the amplitudes (1 = 1/2 + 1/5 + 1/5 + 1/10): the density
    // touches 0, which the paper's rule c_0 >= sum |c_i| allows.
    constexpr double pi = std::numbers::pi;
    FogDesc d;
    d.terms.push_back(FogTerm::constant(1.0));
    d.terms.push_back(FogTerm::cosine(0.5, 5.0 * pi, {0, 1, 0}));
    FogTerm a = FogTerm::cosine(0.2, 1.0, {1, 0, 0});
    a.wave = 7.0 * pi * glm::dvec3(0.1, 1.0, 0.0); // the projection y + 0.1 x is not unit length: keep it as written
    d.terms.push_back(a);
    FogTerm b = FogTerm::cosine(0.2, 1.0, {1, 0, 0});
    b.wave = 5.0 * pi * glm::dvec3(-0.05, 1.0, 0.0);
    d.terms.push_back(b);
    d.terms.push_back(FogTerm::cosineProduct(0.1, pi, {1, 0, 0}, 0.0, 0.5 * pi, {0, 0, 1}, 0.0));
    // The paper gives no far cut-off or colour for this figure: white-grey mist, no cut-off.
    d.colour = {0.85, 0.85, 0.88};
    return d;
}

FogDesc paperFig7Fog(double cellHalfSizeWorld) {
    // "a sum of two simple polynomials of fifth degree with coefficients {0.8, -1, 0, 0, 1}
    // on the two horizontal axes X and Z". Five coefficients make a polynomial of order 5
    // (degree 4); the paper does not say their order nor the cell size C. Read here as
    // ascending powers of u = x / C in the reference cell [-1, 1]: P(u) = 0.8 - u + u^4,
    // positive on the cell (minimum 0.8 - 0.75 * 4^(-1/3) ~ 0.33 at u = 4^(-1/3)), made
    // periodic (Fig. 3). C defaults to 10 world units (an assumption: the paper's scene scale is unknown).
    FogDesc d;
    const std::vector<double> coeffs{0.8, -1.0, 0.0, 0.0, 1.0};
    d.terms.push_back(FogTerm::polynomial1D(1.0, 0, coeffs, cellHalfSizeWorld));
    d.terms.push_back(FogTerm::polynomial1D(1.0, 2, coeffs, cellHalfSizeWorld));
    d.colour = {0.85, 0.85, 0.88};
    return d;
}

FogDesc paperFig8Fog() {
    // "Constant fog with equipotential point functions ... four point equipotential functions
    // centred in the trees". The paper gives neither the constant, the trees' positions nor c, d:
    // chosen here as a light constant fog 0.02 per unit, trees at (+-15, 2, +-15), each
    // potential 0.5 / (1 + 0.05 r^2), i.e. 0.5 per unit at a tree falling to half at r ~ 4.5.
    FogDesc d;
    d.terms.push_back(FogTerm::constant(0.02));
    for (double x : {-15.0, 15.0})
        for (double z : {-15.0, 15.0}) d.terms.push_back(FogTerm::point(0.5, {x, 2.0, z}, 1.0, 0.05));
    d.colour = {0.85, 0.85, 0.88};
    return d;
}

} // namespace splatfx
