// Private: numbers as the grid module's messages show them.
#pragma once

#include <sstream>
#include <string>

namespace splatfx::grid_detail {

// Shortest readable form: "0.25", "-1", "nan", "inf".
inline std::string str(float v) {
    std::ostringstream os;
    os << v;
    return os.str();
}

} // namespace splatfx::grid_detail
