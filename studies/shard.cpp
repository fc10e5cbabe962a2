// studies/shard.cpp: the shard split, the sweep identity and its manifest, and the reference
// shared by the shards of one output folder through an O_EXCL lock file.
#include "studies/shard.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>
#include <algorithm>
#include <atomic>
#include <cerrno>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <fstream>
#include <numeric>
#include <set>
#include <sstream>
#include <thread>
#include <variant>

#include "scene/error.h"
#include "scene/frame_io.h"
#include "scene/json_input.h"
#include "scene/settings.h"
#include "studies/machine.h"

namespace shadowlab::studies {

namespace {

namespace fs = std::filesystem;
using Json = nlohmann::json;

// FNV-1a, 64 bits: stable across machines and runs (std::hash is not).
struct Fnv {
    std::uint64_t h = 1469598103934665603ull;
    void add(const std::string& s) {
        for (unsigned char c : s) h = (h ^ c) * 1099511628211ull;
        h = (h ^ 0xffu) * 1099511628211ull;  // a separator, so ("ab","c") ≠ ("a","bc")
    }
    std::string hex() const {
        char buf[20];
        std::snprintf(buf, sizeof buf, "%016llx", static_cast<unsigned long long>(h));
        return buf;
    }
};

bool addFile(Fnv& f, const fs::path& file) {
    std::ifstream in(file, std::ios::binary);
    if (!in) return false;
    std::ostringstream s;
    s << in.rdbuf();
    f.add(s.str());
    return true;
}

}  // namespace

Shard parseShard(const std::string& text) {
    long long k = -1, n = -1;
    char slash = 0, extra = 0;
    if (std::sscanf(text.c_str(), "%lld%c%lld%c", &k, &slash, &n, &extra) != 3 || slash != '/')
        throw scene::InputError("--shard: expected K/N (shard K of N, K from 0), got '" + text + "'");
    if (n < 1 || n > kMaxShards)
        throw scene::InputError("--shard " + text + ": N must be in 1.." + std::to_string(kMaxShards));
    if (k < 0 || k >= n)
        throw scene::InputError("--shard " + text + ": K must be in 0.." + std::to_string(n - 1) +
                                " (shards are numbered from 0, as Slurm array tasks are)");
    return {int(k), int(n)};
}

std::string shardFolderName(const Shard& shard) {
    return "shard-" + std::to_string(shard.index) + "-of-" + std::to_string(shard.count);
}

std::vector<std::string> gridKeys(const SweepGrid& grid) {
    std::vector<std::string> keys;
    std::set<std::string> seen;
    for (const SweepConfig& c : grid.configs)
        if (std::string k = c.key(); seen.insert(k).second) keys.push_back(std::move(k));
    return keys;
}

std::vector<int> assignShards(const std::vector<std::string>& keys, int count) {
    std::vector<std::size_t> order(keys.size());
    std::iota(order.begin(), order.end(), std::size_t(0));
    std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return keys[a] < keys[b]; });
    std::vector<int> shard(keys.size(), 0);
    for (std::size_t rank = 0; rank < order.size(); ++rank) shard[order[rank]] = int(rank % std::size_t(count));
    return shard;
}

SweepGrid shardGrid(const SweepGrid& grid, const Shard& shard) {
    const std::vector<std::string> keys = gridKeys(grid);
    const std::vector<int> of = assignShards(keys, shard.count);
    std::set<std::string> mine;
    for (std::size_t i = 0; i < keys.size(); ++i)
        if (of[i] == shard.index) mine.insert(keys[i]);
    SweepGrid g = grid;
    g.configs.clear();
    std::set<std::string> taken;
    for (const SweepConfig& c : grid.configs)
        if (const std::string k = c.key(); mine.count(k) && taken.insert(k).second) g.configs.push_back(c);
    return g;
}

std::string sceneHash(const scene::Scene& scene) {
    Fnv f;
    if (!addFile(f, scene.file)) f.add("scene file not readable: " + scene.file.string());
    std::set<fs::path> meshes;
    for (const scene::Object& o : scene.objects)
        if (const auto* m = std::get_if<scene::Mesh>(&o.shape)) meshes.insert(m->file);
    for (const fs::path& m : meshes) {
        f.add(m.filename().string());
        if (!addFile(f, m)) f.add("not readable");
    }
    return f.hex();
}

std::string fileHash(const fs::path& file) {
    Fnv f;
    if (!addFile(f, file)) throw scene::InputError(file.string() + ": cannot read");
    return f.hex();
}

SweepIdentity sweepIdentity(const scene::Scene& scene, const SweepGrid& grid) {
    SweepIdentity id;
    id.version = SHADOWLAB_VERSION;
    id.scene = scene.file.string();
    id.sceneHash = sceneHash(scene);
    id.width = scene.camera.width;
    id.height = scene.camera.height;
    id.repetitions = grid.repetitions;
    id.keys = gridKeys(grid);
    Fnv f;
    for (const std::string& k : id.keys) f.add(k);
    f.add("repetitions=" + std::to_string(grid.repetitions));
    if (grid.flicker) f.add("flicker=" + flickerKey(*grid.flicker));  // only with the axis: other hashes stay
    id.gridHash = f.hex();
    return id;
}

std::string identityDifference(const SweepIdentity& a, const SweepIdentity& b) {
    if (a.version != b.version)
        return "program version " + a.version + " vs " + b.version + " (shards must come from one shadowlab build)";
    if (a.sceneHash != b.sceneHash)
        return "scene hash " + a.sceneHash + " (" + a.scene + ") vs " + b.sceneHash + " (" + b.scene +
               ") (another scene file or mesh)";
    if (a.width != b.width || a.height != b.height)
        return "resolution " + std::to_string(a.width) + "x" + std::to_string(a.height) + " vs " +
               std::to_string(b.width) + "x" + std::to_string(b.height);
    if (a.repetitions != b.repetitions)
        return "repetitions " + std::to_string(a.repetitions) + " vs " + std::to_string(b.repetitions);
    if (a.gridHash != b.gridHash || a.keys != b.keys)
        return "grid hash " + a.gridHash + " (" + std::to_string(a.keys.size()) + " rows) vs " + b.gridHash + " (" +
               std::to_string(b.keys.size()) + " rows) (another grid or other command-line settings)";
    return "";
}

namespace {
std::vector<std::string>& processCommandLine() {
    static std::vector<std::string> line;
    return line;
}
std::string& processDirectory() {
    static std::string dir;
    return dir;
}
}  // namespace

void setCommandLine(std::vector<std::string> arguments) {
    processCommandLine() = std::move(arguments);
    std::error_code ec;
    processDirectory() = processCommandLine().empty() ? std::string() : fs::current_path(ec).string();
}
const std::vector<std::string>& commandLine() { return processCommandLine(); }
std::string commandDirectory() { return processDirectory(); }

RecordedCommand recordedShardCommand(const std::vector<fs::path>& dirs) {
    for (const fs::path& d : dirs) {
        const Json j = scene::readJsonFileOrNull(d / "shard.json");
        if (!j.is_object() || !j.contains("command") || !j["command"].is_array()) continue;
        RecordedCommand out;
        for (const Json& a : j["command"])
            if (a.is_string()) out.args.push_back(a.get<std::string>());
        if (j.contains("cwd") && j["cwd"].is_string()) out.cwd = j["cwd"].get<std::string>();
        if (!out.args.empty()) return out;
    }
    return {};
}

std::string shardCommandText(const std::vector<std::string>& command, const Shard& shard, bool resume,
                             const std::string& cwd) {
    const std::string value = std::to_string(shard.index) + "/" + std::to_string(shard.count);
    std::string text = "shadowlab";
    bool named = false;
    for (std::size_t i = 1; i < command.size(); ++i) {
        const std::string& a = command[i];
        if (a == "--resume") continue;
        if (a == "--shard" && i + 1 < command.size()) {
            text += " --shard " + value;
            named = true;
            ++i;
        } else if (a.rfind("--shard=", 0) == 0) {
            text += " --shard=" + value;
            named = true;
        } else {
            text += " " + quoteArg(a);
        }
    }
    if (command.empty() || !named) return "";
    if (resume) text += " --resume";
    std::error_code ec;
    if (!cwd.empty() && fs::path(cwd) != fs::current_path(ec)) text = "cd " + quoteArg(cwd) + " && " + text;
    return text;
}

std::string quoteArg(const std::string& s) {
    if (!s.empty() && s.find_first_of(" \t\n'\"$\\`;&|<>()*?#~[]{}!") == std::string::npos) return s;
    std::string q = "'";
    for (char c : s) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
    return q + "'";
}

void placeFile(const fs::path& src, const fs::path& dst) {
    std::error_code ec;
    if (fs::exists(dst, ec) && fs::equivalent(src, dst, ec)) return;
    fs::create_directories(dst.parent_path());
    const fs::path tmp = scene::temporarySibling(dst);
    fs::create_hard_link(src, tmp, ec);
    if (ec) {
        ec.clear();
        fs::copy_file(src, tmp, fs::copy_options::overwrite_existing, ec);
        if (ec) {
            fs::remove(tmp, ec);
            throw scene::OutputError(dst.string() + ": cannot copy " + src.string() + " here");
        }
    }
    fs::rename(tmp, dst, ec);
    if (ec) {
        fs::remove(tmp, ec);
        throw scene::OutputError(dst.string() + ": cannot write");
    }
}

Json shardManifest(const SweepIdentity& id, const Shard& shard) {
    return {{"program", "shadowlab"},
            {"command", commandLine()},
            {"cwd", commandDirectory()},
            {"version", id.version},
            {"scene", id.scene},
            {"scene_hash", id.sceneHash},
            {"resolution", {id.width, id.height}},
            {"repetitions", id.repetitions},
            {"grid_hash", id.gridHash},
            {"shard", {{"index", shard.index}, {"count", shard.count}}},
            {"keys", id.keys}};
}

void readShardManifest(const fs::path& file, SweepIdentity& id, Shard& shard) {
    const Json j = scene::readJsonFile(file);
    const char* field = "";
    try {
        field = "program";
        if (j.at(field).get<std::string>() != "shadowlab") throw std::runtime_error("not shadowlab");
        field = "version";
        id.version = j.at(field).get<std::string>();
        field = "scene";
        id.scene = j.at(field).get<std::string>();
        field = "scene_hash";
        id.sceneHash = j.at(field).get<std::string>();
        field = "resolution";
        id.width = j.at(field).at(0).get<int>();
        id.height = j.at(field).at(1).get<int>();
        field = "repetitions";
        id.repetitions = j.at(field).get<int>();
        field = "grid_hash";
        id.gridHash = j.at(field).get<std::string>();
        field = "keys";
        id.keys = j.at(field).get<std::vector<std::string>>();
        field = "shard";
        shard.index = j.at(field).at("index").get<int>();
        shard.count = j.at(field).at("count").get<int>();
    } catch (const std::exception& e) {
        throw scene::InputError(file.string() + ": " + field + ": missing or wrong type in the shard manifest");
    }
    if (shard.count < 1 || shard.index < 0 || shard.index >= shard.count)
        throw scene::InputError(file.string() + ": shard: index " + std::to_string(shard.index) + " of " +
                                std::to_string(shard.count) + " is out of range");
}

std::string referenceTag(const scene::Scene& scene) {
    return sceneHash(scene) + " " + std::to_string(scene.camera.width) + "x" + std::to_string(scene.camera.height) +
           " " + SHADOWLAB_VERSION;
}

std::string referenceTag(const SweepIdentity& id) {
    return id.sceneHash + " " + std::to_string(id.width) + "x" + std::to_string(id.height) + " " + id.version;
}

namespace {

// The lock's holder: host and pid, so a shard on the same host can tell a dead holder at once.
std::string lockOwner() { return currentMachine().host + " " + std::to_string(::getpid()); }

bool holderIsDeadHere(const fs::path& lock) {
    std::ifstream in(lock);
    std::string host;
    long pid = 0;
    if (!(in >> host >> pid) || pid <= 0) return false;
    return host == currentMachine().host && ::kill(pid_t(pid), 0) != 0 && errno == ESRCH;
}

// The lock's mtime as a value to watch for change (the clocks of the machines need not agree).
long long stamp(const fs::path& lock) {
    struct stat st {};
    if (::stat(lock.c_str(), &st) != 0) return -1;
    return static_cast<long long>(st.st_mtim.tv_sec) * 1000000000LL + st.st_mtim.tv_nsec;
}

}  // namespace

scene::Frame sharedReference(const fs::path& dir, const scene::Scene& scene,
                             const std::function<scene::Frame()>& render, const SharedReferenceOptions& options) {
    using Clock = std::chrono::steady_clock;
    const fs::path file = dir / "reference.exr";
    const fs::path lock = dir / "reference.exr.lock";
    const std::string tag = referenceTag(scene);
    fs::create_directories(dir);
    bool said = false;
    long long lastStamp = -2;
    auto lastChange = Clock::now();
    for (;;) {
        std::error_code ec;
        if (fs::exists(file, ec)) {
            scene::Frame f = scene::readFrame(file);
            const auto it = f.attributes.find("reference_of");
            if (it == f.attributes.end() || it->second != tag)
                throw scene::InputError(file.string() + ": the reference of another sweep (" +
                                        (it == f.attributes.end() ? std::string("untagged") : it->second) +
                                        ", this one is " + tag + "); choose another output folder");
            return f;
        }
        const int fd = ::open(lock.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0644);
        if (fd >= 0) {
            const std::string owner = lockOwner() + "\n";
            const bool wrote = ::write(fd, owner.data(), owner.size()) == ssize_t(owner.size());
            ::close(fd);
            if (!wrote) {
                fs::remove(lock, ec);
                throw scene::OutputError(lock.string() + ": cannot write (disk full?)");
            }
            // Refresh the lock while rendering, so waiting shards can tell a live holder from a dead one.
            std::atomic<bool> stop{false};
            std::thread heartbeat([&] {
                auto next = Clock::now();
                while (!stop) {
                    if (Clock::now() >= next) {
                        ::utimensat(AT_FDCWD, lock.c_str(), nullptr, 0);
                        next = Clock::now() + std::chrono::duration_cast<Clock::duration>(
                                                  std::chrono::duration<double>(options.staleSeconds / 6.0));
                    }
                    std::this_thread::sleep_for(std::chrono::milliseconds(50));
                }
            });
            try {
                scene::Frame f = render();
                f.attributes["reference_of"] = tag;
                scene::writePngLinear(dir / "reference.png", f.width, f.height, f.beauty);
                scene::writeFrame(f, file);  // last: its presence means both are complete
                stop = true;
                heartbeat.join();
                fs::remove(lock, ec);
                return f;
            } catch (...) {
                stop = true;
                heartbeat.join();
                fs::remove(lock, ec);
                throw;
            }
        }
        if (errno != EEXIST) throw scene::InputError(lock.string() + ": cannot create the reference lock");
        if (!said && options.log) {
            options.log("waiting for the reference another shard is rendering (" + lock.string() + ")");
            said = true;
        }
        const long long s = stamp(lock);
        if (s != lastStamp) {
            lastStamp = s;
            lastChange = Clock::now();
        }
        const bool stale = std::chrono::duration<double>(Clock::now() - lastChange).count() > options.staleSeconds;
        if (s >= 0 && (stale || holderIsDeadHere(lock))) {
            // Its holder died: move it aside first, so two waiters cannot both remove a fresh lock.
            const fs::path aside = scene::temporarySibling(lock);
            fs::rename(lock, aside, ec);
            fs::remove(aside, ec);
            if (options.log) options.log("took over the reference from a stopped shard");
            continue;
        }
        std::this_thread::sleep_for(std::chrono::duration<double>(options.pollSeconds));
    }
}

SweepResult runShard(const scene::Scene& baseScene, const SweepGrid& grid, const Shard& shard,
                     const SweepOptions& options, const SharedReferenceOptions& referenceOptions) {
    const scene::Scene scene = sweepScene(baseScene, grid);
    const SweepIdentity id = sweepIdentity(scene, grid);
    const fs::path dir = options.outputDir / shardFolderName(shard);
    const fs::path manifest = dir / "shard.json";
    std::error_code ec;
    if (fs::exists(manifest, ec)) {
        SweepIdentity old;
        Shard oldShard;
        readShardManifest(manifest, old, oldShard);
        if (const std::string d = identityDifference(old, id); !d.empty())
            throw scene::InputError(dir.string() + ": holds a shard of another sweep (" + d +
                                    "); choose another folder");
    }
    // Refused before anything is written, as runSweep would refuse it.
    if (fs::exists(dir / "results.jsonl", ec) && !options.resume)
        throw scene::InputError(dir.string() +
                                ": already holds this shard (results.jsonl); use --resume to "
                                "continue it, or choose another folder");
    fs::create_directories(dir);
    scene::writeTextAtomic(manifest, shardManifest(id, shard).dump(1) + "\n");

    SweepOptions o = options;
    o.outputDir = dir;
    const SweepGrid mine = shardGrid(grid, shard);
    if (mine.configs.empty()) {
        // More shards than rows: this one has nothing to compare, so it needs no reference.
        o.reference = [](const scene::Scene&) { return scene::Frame{}; };
        return runSweep(scene, mine, o);
    }
    const RenderFn render = options.render;
    const fs::path shared = options.outputDir;
    o.reference = [render, shared, referenceOptions](const scene::Scene& sc) {
        return sharedReference(
            shared, sc,
            [&] {
                const scene::RenderSettings settings = scene::resolveSettings(sc, {});
                scene::Frame f = render(sc, settings, scene::Backend::Reference);
                f.attributes["scene"] = sc.file.string();
                return f;
            },
            referenceOptions);
    };
    return runSweep(scene, mine, o);
}

}  // namespace shadowlab::studies
