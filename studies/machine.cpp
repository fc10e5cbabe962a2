// studies/machine.cpp: reads the host name, CPU model, usable cores and load average.
#include "studies/machine.h"

#include <sched.h>
#include <unistd.h>
#include <cstdlib>
#include <fstream>

namespace shadowlab::studies {

namespace {

std::string trim(const std::string& s) {
    const auto b = s.find_first_not_of(" \t");
    const auto e = s.find_last_not_of(" \t\r\n");
    return b == std::string::npos ? std::string() : s.substr(b, e - b + 1);
}

// x86 names the model in "model name"; ARM kernels give "Hardware" or only "CPU part".
std::string cpuModel() {
    std::ifstream in("/proc/cpuinfo");
    std::string line, fallback;
    while (std::getline(in, line)) {
        const auto colon = line.find(':');
        if (colon == std::string::npos) continue;
        const std::string key = trim(line.substr(0, colon)), value = trim(line.substr(colon + 1));
        if (key == "model name" && !value.empty()) return value;
        if ((key == "Hardware" || key == "CPU part" || key == "cpu model") && fallback.empty()) fallback = value;
    }
    return fallback.empty() ? "unknown CPU" : fallback;
}

}  // namespace

std::string MachineInfo::id() const { return host + "|" + cpu + "|" + std::to_string(cores); }

std::string MachineInfo::describe() const {
    std::string s = (host.empty() ? std::string("unknown host") : host) + " (" + cpu + ", ";
    s += onlineCores > 0 && onlineCores != cores
             ? std::to_string(cores) + " of " + std::to_string(onlineCores) + " cores"
             : std::to_string(cores) + " cores";
    return s + ")";
}

MachineInfo currentMachine() {
    MachineInfo m;
    char host[256] = {};
    if (::gethostname(host, sizeof host - 1) == 0) m.host = host;
    m.cpu = cpuModel();
    cpu_set_t set;
    CPU_ZERO(&set);
    m.onlineCores = int(::sysconf(_SC_NPROCESSORS_ONLN));
    m.cores = ::sched_getaffinity(0, sizeof set, &set) == 0 ? CPU_COUNT(&set) : m.onlineCores;
    double load[1] = {0.0};
    if (::getloadavg(load, 1) == 1) m.load = load[0];
    return m;
}

nlohmann::json toJson(const MachineInfo& m) {
    return {{"host", m.host}, {"cpu", m.cpu}, {"cores", m.cores}, {"online_cores", m.onlineCores}, {"load", m.load}};
}

MachineInfo machineFromJson(const nlohmann::json& j) {
    MachineInfo m;
    if (!j.is_object()) return m;
    m.host = j.value("host", "");
    m.cpu = j.value("cpu", "");
    m.cores = j.value("cores", 0);
    m.onlineCores = j.value("online_cores", 0);
    m.load = j.value("load", 0.0);
    return m;
}

}  // namespace shadowlab::studies
