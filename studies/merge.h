// studies/merge.h: joins the shards of one sweep (studies/shard.h) into the folder an unsharded
// sweep writes: results.jsonl, results.csv, results.json, images/, reference.exr/.png, and
// merge.json (which shards, which machines); the app then writes the report from the rows.
// Every input is read and checked before anything is written, and every file is written to a
// temporary name and renamed, so a refused or failed merge leaves no merged file half written.
#pragma once

#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "studies/shard.h"
#include "studies/sweep.h"
#include "studies/sweep_report.h"

namespace shadowlab::studies {

struct MergedSweep {
    SweepIdentity identity;
    int shardCount = 0;
    std::vector<SweepRow> rows;                    // grid order, one per key
    std::vector<std::filesystem::path> rowSource;  // the shard folder each row comes from
    std::vector<std::filesystem::path> shardDirs;  // every shard folder read (reruns included)
    std::size_t duplicates = 0;                    // rows found in more than one journal, merged once
    std::filesystem::path reference;               // a reference.exr of this sweep; empty: none found
};

// Reads the shards under `inputs` (each a shard folder, holding shard.json, or a folder holding
// shard-K-of-N folders). Throws scene::InputError, naming the folder or file:line, when an input
// is missing or holds no shard, a journal line is damaged, shards belong to different sweeps
// (version, scene hash, resolution, repetitions, grid) or splits, a row is in the wrong shard, or
// rows are missing: then every missing or unfinished shard is named with the command that
// renders its rows (`sweep --shard K/N`, with `--resume` when it started).
MergedSweep readShards(const std::vector<std::filesystem::path>& inputs);

// Writes the merged folder `out` (see above). Refuses a shard folder and a folder that holds an
// unsharded sweep (scene::InputError), before writing anything.
void writeMerged(const MergedSweep& merged, const std::filesystem::path& out);

// The report input of a merged folder written by writeMerged.
SweepReportInput mergedReportInput(const MergedSweep& merged, const std::filesystem::path& out);

// What differs between two sweeps' rows, ignoring what timing measures (run times, stage and GPU
// pass times, the machine) and image paths: one line per difference, empty when they hold the same rows
// (keys, settings, metrics and errors), in the same order.
std::vector<std::string> rowDifferences(const std::vector<SweepRow>& a, const std::vector<SweepRow>& b);

// What differs between the verdicts two sweeps' rows give (recommendBias: each series' window
// or "stiff", its recommended value and dominant artifact; which robust offsets pass), leaving
// out the choices made by run time (the fastest passing robust precision).
std::vector<std::string> verdictDifferences(const std::vector<SweepRow>& a, const std::vector<SweepRow>& b);

// The rows of a finished sweep or merged folder (DIR/results.json). Throws scene::InputError.
std::vector<SweepRow> readResults(const std::filesystem::path& dir);

}  // namespace shadowlab::studies
