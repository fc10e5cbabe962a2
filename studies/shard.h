// studies/shard.h: one sweep split over N independent processes (`sweep --shard K/N`, a Slurm
// job array, GNU parallel, a CI matrix). Rows are dealt round-robin over the sorted row keys,
// so shards are disjoint, cover the grid and differ in size by at most one row. Each shard is a
// sweep folder of its own (DIR/shard-K-of-N) with a manifest naming the sweep it belongs to; the
// reference is rendered once per DIR and shared. studies/merge.h joins the shards.
#pragma once

#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "studies/sweep.h"

namespace shadowlab::studies {

struct Shard {
    int index = 0;  // K, 0-based (a Slurm array task id)
    int count = 1;  // N
};

// "K/N" with 0 ≤ K < N ≤ kMaxShards. Throws scene::InputError naming what is wrong.
inline constexpr int kMaxShards = 100000;
Shard parseShard(const std::string& text);
std::string shardFolderName(const Shard& shard);  // "shard-2-of-4"

// The grid's distinct row keys in grid order (a configuration named twice is one row).
std::vector<std::string> gridKeys(const SweepGrid& grid);
// The shard index of each key: the keys are sorted and dealt out round-robin, so the split
// depends only on the set of keys, never on the order a grid file lists them.
std::vector<int> assignShards(const std::vector<std::string>& keys, int count);
// The configurations of `shard`, in grid order.
SweepGrid shardGrid(const SweepGrid& grid, const Shard& shard);

// What shards of one sweep share and shards of another do not: program version, scene (a hash of
// the scene file and the mesh files it names), resolution, repetitions and the grid (a hash of
// its keys). The scene's path is kept for messages but not compared: a shared file system may be
// mounted at different places on different machines.
struct SweepIdentity {
    std::string version;
    std::string scene;      // path, as given on the machine that wrote it
    std::string sceneHash;  // 16 hex digits
    int width = 0, height = 0;
    int repetitions = 0;
    std::string gridHash;           // 16 hex digits over keys (in grid order) and repetitions
    std::vector<std::string> keys;  // the whole grid's row keys, in grid order
};

// `scene` as the sweep renders it (sweepScene: the grid's resolution applied).
SweepIdentity sweepIdentity(const scene::Scene& scene, const SweepGrid& grid);
std::string sceneHash(const scene::Scene& scene);
// The same 64-bit FNV-1a hash over one file's bytes (16 hex digits); throws scene::InputError
// when it cannot be read.
std::string fileHash(const std::filesystem::path& file);
// The first field in which two identities differ, in words ("scene_hash 0123… vs 4567… (another
// scene file or mesh)"); empty when they are of one sweep.
std::string identityDifference(const SweepIdentity& a, const SweepIdentity& b);

// This process's command line and working folder (main sets them), recorded as "command" and
// "cwd" in every shard manifest so that merge can name the exact command that renders a missing or
// unfinished shard.
void setCommandLine(std::vector<std::string> arguments);
const std::vector<std::string>& commandLine();
std::string commandDirectory();  // the working folder when setCommandLine ran; "" before
struct RecordedCommand {
    std::vector<std::string> args;
    std::string cwd;  // where it ran; relative paths in args are relative to it
};
// The command recorded in the first of `dirs`' shard.json that has one; empty args when none does.
RecordedCommand recordedShardCommand(const std::vector<std::filesystem::path>& dirs);
// `command` (a shard's recorded command line) for `shard`: its --shard value replaced, --resume
// dropped or added, the program named "shadowlab", each argument quoted for a POSIX shell, and
// "cd CWD && " in front when it ran in another folder than this process; empty when `command` is,
// or names no --shard.
std::string shardCommandText(const std::vector<std::string>& command, const Shard& shard, bool resume,
                             const std::string& cwd = "");
// `s` quoted for a POSIX shell when it is empty or holds a character the shell reads specially.
std::string quoteArg(const std::string& s);
// Links src to dst (same file system) or copies it, through a temporary name; creates dst's
// folder. Throws scene::InputError naming dst when it cannot.
void placeFile(const std::filesystem::path& src, const std::filesystem::path& dst);

// DIR/shard-K-of-N/shard.json.
nlohmann::json shardManifest(const SweepIdentity& identity, const Shard& shard);
// Throws scene::InputError naming the file and the field when the manifest is not one.
void readShardManifest(const std::filesystem::path& file, SweepIdentity& identity, Shard& shard);

struct SharedReferenceOptions {
    // A lock whose holder stopped refreshing it this long ago is stale (its shard died while
    // rendering the reference): the next shard takes over.
    double staleSeconds = 60.0;
    double pollSeconds = 0.2;
    std::function<void(const std::string&)> log;  // "waiting for ..." messages; may be empty
};

// The reference of `scene` shared through `dir`: reads dir/reference.exr when it is there; else
// the first caller takes dir/reference.exr.lock (O_EXCL), renders, writes reference.exr and
// reference.png atomically and drops the lock, while the others wait for it. Throws
// scene::InputError when dir/reference.exr is the reference of another scene or resolution.
scene::Frame sharedReference(const std::filesystem::path& dir, const scene::Scene& scene,
                             const std::function<scene::Frame()>& render, const SharedReferenceOptions& options = {});
// The tag a shared reference carries (its "reference_of" attribute): scene hash, size, version.
std::string referenceTag(const scene::Scene& scene);
std::string referenceTag(const SweepIdentity& identity);

// Runs `shard` of `grid` into options.outputDir / shardFolderName(shard): writes shard.json
// (refusing a folder that holds a shard of another sweep or another K/N), takes the shared
// reference from options.outputDir, then runs runSweep on the shard's rows (resume as asked).
SweepResult runShard(const scene::Scene& scene, const SweepGrid& grid, const Shard& shard, const SweepOptions& options,
                     const SharedReferenceOptions& referenceOptions = {});

}  // namespace shadowlab::studies
