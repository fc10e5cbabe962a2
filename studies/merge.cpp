// studies/merge.cpp: reads and checks shard folders, joins their journals in grid order, and
// writes the merged sweep folder.
#include "studies/merge.h"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <map>
#include <set>
#include <sstream>

#include "scene/append_line.h"
#include "scene/error.h"
#include "scene/frame_io.h"
#include "scene/json_input.h"
#include "studies/auto_bias.h"
#include "studies/machine.h"

namespace shadowlab::studies {

namespace {

namespace fs = std::filesystem;
using Json = nlohmann::json;

struct ShardFolder {
    fs::path dir;
    SweepIdentity identity;
    Shard shard;
};

// A journal read strictly: a line that is not a row is an error naming file:line, except a last
// line without its newline, which is what a kill in the middle of a write leaves (its row did not
// finish and counts as missing).
std::vector<SweepRow> readJournalStrict(const fs::path& file) {
    std::vector<SweepRow> rows;  // none when the shard started but finished no row
    for (const scene::JournalLine& l : scene::readJournalLines(file)) {
        try {
            SweepRow r = rowFromJournal(Json::parse(l.text));
            if (r.key.empty()) throw std::runtime_error("empty key");
            rows.push_back(std::move(r));
        } catch (const std::exception& e) {
            if (l.torn) break;
            std::string what = e.what();
            if (const auto p = what.find("] "); p != std::string::npos) what = what.substr(p + 2);
            throw scene::InputError(file.string() + ":" + std::to_string(l.number) +
                                    ": damaged journal line (not a sweep row: " + what + ")");
        }
    }
    return rows;
}

std::vector<ShardFolder> findShards(const std::vector<fs::path>& inputs) {
    std::vector<ShardFolder> shards;
    std::error_code ec;
    for (const fs::path& in : inputs) {
        if (!fs::is_directory(in, ec)) throw scene::InputError(in.string() + ": no such folder");
        std::vector<fs::path> dirs;
        if (fs::exists(in / "shard.json", ec)) {
            dirs.push_back(in);
        } else {
            for (const auto& e : fs::directory_iterator(in, ec))
                if (e.is_directory() && e.path().filename().string().rfind("shard-", 0) == 0 &&
                    fs::exists(e.path() / "shard.json"))
                    dirs.push_back(e.path());
            std::sort(dirs.begin(), dirs.end());
        }
        if (dirs.empty())
            throw scene::InputError(in.string() + ": holds no shard (neither shard.json nor a shard-K-of-N folder)");
        for (const fs::path& d : dirs) {
            ShardFolder s;
            s.dir = d;
            readShardManifest(d / "shard.json", s.identity, s.shard);
            shards.push_back(std::move(s));
        }
    }
    return shards;
}

// The row as compared between sweeps: what timing measures (the row's times, the stage times in
// its metrics, the GPU pass times in its settings, the machine) and where images are left out.
Json comparable(const SweepRow& r) {
    Json j = journalRow(r);
    for (const char* k : {"setup_ms", "frame_ms", "frame_ms_min", "frame_ms_max", "machine", "image", "diff_image"})
        j.erase(k);
    if (j["metrics"].is_object()) {
        j["metrics"].erase("method_timing");
        j["metrics"].erase("reference_timing");
    }
    if (j["settings"].is_object())
        for (auto it = j["settings"].begin(); it != j["settings"].end();)
            it = it.key().size() > 3 && it.key().ends_with("_ms") ? j["settings"].erase(it) : std::next(it);
    return j;
}

// A bias verdict as compared: the window or "stiff", the recommended value and the dominant artifact.
Json verdictOf(const BiasSeries& s) {
    auto num = [](double v) { return std::isfinite(v) ? Json(v) : Json(nullptr); };  // NaN ≠ NaN
    return {{"kind", s.kind},
            {"backend", scene::toString(s.backend)},
            {"context", s.context},
            {"stiff", s.window.stiff},
            {"lo", num(s.window.lo)},
            {"hi", num(s.window.hi)},
            {"recommended", num(s.recommended)},
            {"dominant", s.dominant}};
}

}  // namespace

MergedSweep readShards(const std::vector<fs::path>& inputs) {
    if (inputs.empty()) throw scene::InputError("merge: give at least one folder of shards");
    const std::vector<ShardFolder> shards = findShards(inputs);
    MergedSweep m;
    m.identity = shards.front().identity;
    m.shardCount = shards.front().shard.count;
    for (const ShardFolder& s : shards) {
        if (const std::string d = identityDifference(shards.front().identity, s.identity); !d.empty())
            throw scene::InputError(s.dir.string() + " and " + shards.front().dir.string() +
                                    " are shards of different sweeps: " + d);
        if (s.shard.count != m.shardCount)
            throw scene::InputError(s.dir.string() + " is shard " + std::to_string(s.shard.index) + "/" +
                                    std::to_string(s.shard.count) + " but " + shards.front().dir.string() + " is " +
                                    std::to_string(shards.front().shard.index) + "/" + std::to_string(m.shardCount) +
                                    ": shards of different splits do not merge");
        m.shardDirs.push_back(s.dir);
    }

    const std::vector<std::string>& keys = m.identity.keys;
    const std::vector<int> owner = assignShards(keys, m.shardCount);
    std::map<std::string, std::size_t> index;
    for (std::size_t i = 0; i < keys.size(); ++i) index[keys[i]] = i;

    std::vector<std::optional<SweepRow>> found(keys.size());
    std::vector<fs::path> source(keys.size());
    std::set<int> present;
    for (const ShardFolder& s : shards) {
        present.insert(s.shard.index);
        const fs::path journal = s.dir / "results.jsonl";
        for (SweepRow& r : readJournalStrict(journal)) {
            const auto it = index.find(r.key);
            if (it == index.end())
                throw scene::InputError(journal.string() + ": row '" + r.key + "' is not in the sweep's grid");
            const std::size_t i = it->second;
            if (owner[i] != s.shard.index)
                throw scene::InputError(journal.string() + ": row '" + r.key + "' belongs to shard " +
                                        std::to_string(owner[i]) + "/" + std::to_string(m.shardCount) + ", not " +
                                        std::to_string(s.shard.index) + "/" + std::to_string(m.shardCount));
            if (found[i]) {
                ++m.duplicates;
                // A rerun: keep the first finished row; a row that failed gives way to one that did not.
                if (found[i]->error.empty() || !r.error.empty()) continue;
            }
            found[i] = std::move(r);
            source[i] = s.dir;
        }
    }

    // Everything that is missing, in one message, each shard with the command that completes it: a
    // shard's own recorded command line, else the scene and folder with the grid left to the user.
    std::vector<std::string> problems;
    const fs::path base = shards.front().dir.parent_path();
    const std::string scene = quoteArg(m.identity.scene);
    std::vector<fs::path> dirs;
    for (const ShardFolder& s : shards) dirs.push_back(s.dir);
    const RecordedCommand recorded = recordedShardCommand(dirs);
    auto command = [&](int k, bool resume) {
        const std::string c = shardCommandText(recorded.args, {k, m.shardCount}, resume, recorded.cwd);
        if (!c.empty()) return "`" + c + "`";
        return "`shadowlab sweep " + scene + " -o " + quoteArg(base.string()) + " --shard " + std::to_string(k) + "/" +
               std::to_string(m.shardCount) + (resume ? " --resume" : "") + "` and the same grid options";
    };
    for (int k = 0; k < m.shardCount; ++k) {
        std::size_t total = 0, missing = 0;
        for (std::size_t i = 0; i < keys.size(); ++i)
            if (owner[i] == k) {
                ++total;
                missing += found[i] ? 0 : 1;
            }
        const std::string name = std::to_string(k) + "/" + std::to_string(m.shardCount);
        if (!present.count(k)) {
            problems.push_back("shard " + name + " is missing (no " + shardFolderName({k, m.shardCount}) +
                               " among the inputs; " + std::to_string(total) + " rows): render it with " +
                               command(k, false));
        } else if (missing > 0) {
            problems.push_back("shard " + name + " is unfinished (" + std::to_string(missing) + " of " +
                               std::to_string(total) + " rows missing): finish it with " + command(k, true));
        }
    }
    if (!problems.empty()) {
        std::string what = "merge: " + std::to_string(problems.size()) + " of " + std::to_string(m.shardCount) +
                           " shards incomplete; nothing written:";
        for (const std::string& p : problems) what += "\n  " + p;
        throw scene::InputError(what);
    }
    for (std::size_t i = 0; i < keys.size(); ++i) {
        m.rows.push_back(std::move(*found[i]));
        m.rowSource.push_back(source[i]);
    }
    // A reference of this sweep: beside the shards (the shared one) or in a shard folder.
    const std::string tag = referenceTag(m.identity);
    std::set<fs::path> candidates;
    for (const ShardFolder& s : shards)
        for (const fs::path& f : {s.dir.parent_path() / "reference.exr", s.dir / "reference.exr"})
            if (std::error_code ec; fs::exists(f, ec) && !candidates.count(f) && m.reference.empty()) {
                candidates.insert(f);
                try {
                    const scene::Frame ref = scene::readFrame(f);
                    const auto it = ref.attributes.find("reference_of");
                    if (it != ref.attributes.end() && it->second == tag) m.reference = f;
                } catch (const std::exception&) {
                    // a damaged reference: look further
                }
            }
    return m;
}

void writeMerged(const MergedSweep& m, const fs::path& out) {
    std::error_code ec;
    if (fs::exists(out / "shard.json", ec))
        throw scene::InputError(out.string() +
                                ": is a shard folder (shard.json), whose journal the merge would "
                                "overwrite; merge into the folder above it or another one");
    if (fs::exists(out / "sweep.json", ec) && !fs::exists(out / "merge.json", ec))
        throw scene::InputError(out.string() + ": holds an unsharded sweep (sweep.json); merge into another folder");
    fs::create_directories(out / "images");
    std::vector<SweepRow> rows = m.rows;
    for (std::size_t i = 0; i < rows.size(); ++i)
        for (const std::string* image : {&rows[i].image, &rows[i].diffImage})
            if (!image->empty() && fs::exists(m.rowSource[i] / *image, ec))
                placeFile(m.rowSource[i] / *image, out / *image);
    if (!m.reference.empty()) {
        placeFile(m.reference, out / "reference.exr");
        if (fs::exists(m.reference.parent_path() / "reference.png", ec))
            placeFile(m.reference.parent_path() / "reference.png", out / "reference.png");
    }
    std::string journal;
    for (const SweepRow& r : rows) journal += journalRow(r).dump() + "\n";
    std::map<std::string, std::pair<MachineInfo, std::size_t>> machines;
    for (const SweepRow& r : rows) {
        const MachineInfo mi = machineFromJson(r.machine);
        auto& slot = machines[mi.id()];
        slot.first = mi;
        ++slot.second;
    }
    Json machineList = Json::array();
    for (const auto& [id, entry] : machines) {
        Json j = toJson(entry.first);
        j.erase("load");
        j["rows"] = entry.second;
        machineList.push_back(j);
    }
    Json dirs = Json::array();
    for (const fs::path& d : m.shardDirs) dirs.push_back(d.string());
    Json manifest = shardManifest(m.identity, {0, m.shardCount});
    manifest.erase("shard");
    manifest.erase("keys");
    manifest["shards"] = m.shardCount;
    manifest["rows"] = rows.size();
    manifest["duplicates_merged"] = m.duplicates;
    manifest["shard_folders"] = dirs;
    manifest["machines"] = machineList;
    scene::writeTextAtomic(out / "results.jsonl", journal);
    scene::writeTextAtomic(out / "results.csv", rowsToCsv(rows));
    scene::writeTextAtomic(out / "results.json", rowsToJson(rows).dump(1) + "\n");
    scene::writeTextAtomic(out / "merge.json", manifest.dump(2) + "\n");
}

SweepReportInput mergedReportInput(const MergedSweep& m, const fs::path& out) {
    SweepReportInput in;
    in.sceneName = fs::path(m.identity.scene).stem().string();
    in.scenePath = m.identity.scene;
    in.rows = m.rows;
    in.width = m.identity.width;
    in.height = m.identity.height;
    std::error_code ec;
    in.referencePng = fs::exists(out / "reference.png", ec) ? "reference.png" : "";
    if (!m.reference.empty()) {
        try {
            in.referenceMs = scene::readFrame(m.reference).totalTimeMs();
        } catch (const std::exception&) {
            in.referenceMs = 0.0;
        }
    }
    return in;
}

std::vector<std::string> rowDifferences(const std::vector<SweepRow>& a, const std::vector<SweepRow>& b) {
    std::vector<std::string> d;
    if (a.size() != b.size()) d.push_back(std::to_string(a.size()) + " rows vs " + std::to_string(b.size()));
    for (std::size_t i = 0; i < std::min(a.size(), b.size()); ++i) {
        const Json x = comparable(a[i]), y = comparable(b[i]);
        if (x == y) continue;
        std::string what = "row " + std::to_string(i + 1) + " (" + a[i].key + "):";
        for (const auto& [k, v] : x.items())
            if (!y.contains(k) || y[k] != v)
                what += " " + k + " " + v.dump() + " vs " + (y.contains(k) ? y[k].dump() : "absent") + ";";
        for (const auto& [k, v] : y.items())
            if (!x.contains(k)) what += " " + k + " absent vs " + v.dump() + ";";
        d.push_back(what);
    }
    return d;
}

std::vector<std::string> verdictDifferences(const std::vector<SweepRow>& a, const std::vector<SweepRow>& b) {
    const AutoBias x = recommendBias(a), y = recommendBias(b);
    std::vector<std::string> d;
    Json vx = Json::array(), vy = Json::array();
    for (const BiasSeries& s : x.series) vx.push_back(verdictOf(s));
    for (const BiasSeries& s : y.series) vy.push_back(verdictOf(s));
    if (vx != vy) d.push_back("bias verdicts differ: " + vx.dump() + " vs " + vy.dump());
    Json rx = Json::array(), ry = Json::array();
    for (const RobustResult& r : x.robust) rx.push_back({r.precision, r.passes});
    for (const RobustResult& r : y.robust) ry.push_back({r.precision, r.passes});
    if (rx != ry) d.push_back("robust-offset verdicts differ: " + rx.dump() + " vs " + ry.dump());
    return d;
}

std::vector<SweepRow> readResults(const fs::path& dir) {
    const fs::path file = dir / "results.json";
    const Json all = scene::readJsonFile(file);
    std::vector<SweepRow> rows;
    try {
        for (const Json& j : all) rows.push_back(rowFromJournal(j));
    } catch (const std::exception& e) {  // JSON that is not rows, or a backend no build has
        throw scene::InputError(file.string() + ": not a sweep's results (" + std::string(e.what()) + ")");
    }
    return rows;
}

}  // namespace shadowlab::studies
