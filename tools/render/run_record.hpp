// The run record of splatfx-render: what a run (a full run or a farm task)
// was asked for, everything that decides a frame's pixels, and the content
// hash of each frame it wrote. It is written as part of the run's output set
// (DIR/.<set>.run), so it is published with the frames it describes;
// --assemble accepts a frame only if a record with the sequence's settings
// lists it with the hash of the file now in DIR.
//
// The hashes are 64-bit FNV-1a: they catch mistakes (another seed, a stale
// or hand-placed file), not a forger.
#pragma once

#include <map>
#include <string>
#include <utility>
#include <vector>

#include "splatfx/result.hpp"

namespace render {

// The settings that decide the pixels, in a fixed order: name, value.
using RunSettings = std::vector<std::pair<std::string, std::string>>;

std::string contentHash(const std::string& bytes);
// The file's bytes hashed; an error names the file.
splatfx::Result<std::string> hashFile(const std::string& path);

struct RunRecord {
    std::string path; // where it was read from (for messages)
    RunSettings settings;
    std::map<std::string, std::pair<int, std::string>> frames; // file -> (index, hash)
};

std::string recordText(const RunSettings& settings, const std::map<std::string, std::pair<int, std::string>>& frames);
// Every run record in `folder` (DIR/.*.run); files that do not parse are skipped.
std::vector<RunRecord> readRunRecords(const std::string& folder);

// "" if `record` was made with `wanted`, else the first difference, e.g.
// "seed 7 (this sequence: 1)".
std::string settingsDiffer(const RunSettings& record, const RunSettings& wanted);

} // namespace render
