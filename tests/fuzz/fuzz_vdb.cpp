// libFuzzer target for OpenVDB files through the SDK's importer
// (splatfx::loadVdb: the structure walk of vdb_file_check, then OpenVDB's
// reader, then the resampling). The bytes are written to a .vdb file and
// loaded with the default grid names and with density alone (so inputs
// without temperature or velocity grids reach the voxels too), with budgets
// small enough that an accepted input is cheap. Any bytes must give a
// sequence or a message, within the fuzzer's memory and time limits.
#include <cstddef>
#include <cstdint>

#include "fuzz_common.hpp"
#include "splatfx/vdb.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    const std::string path = fuzz::writeFile("fuzz.vdb", data, size);
    splatfx::VdbImportDesc full;
    full.maxFileVoxels = std::uint64_t(1) << 22;
    full.maxTreeBytes = std::uint64_t(1) << 28;
    full.maxSequenceVoxels = std::uint64_t(1) << 23;
    full.maxCellsPerAxis = 16;
    splatfx::VdbImportDesc densityOnly = full;
    densityOnly.temperatureGrid = "";
    densityOnly.velocityGrid = "";
    for (const splatfx::VdbImportDesc& desc : {full, densityOnly}) {
        auto seq = splatfx::loadVdb(path, desc);
        if (!seq && seq.error().empty()) __builtin_trap();
        if (seq && (seq->frames.size() != 1 || !seq->validate())) __builtin_trap();
    }
    return 0;
}
