// studies/machine.h: the machine a sweep row was timed on (host, CPU model, cores, load), so a
// report can tell when run times come from different machines and are not comparable.
#pragma once

#include <string>

#include <nlohmann/json.hpp>

namespace shadowlab::studies {

struct MachineInfo {
    std::string host;     // gethostname()
    std::string cpu;      // /proc/cpuinfo "model name" (or the closest field the CPU has)
    int cores = 0;        // CPUs this process may run on (its affinity mask: a Slurm allocation)
    int onlineCores = 0;  // CPUs the machine has online
    double load = 0.0;    // 1-minute load average when the row finished

    // What makes two rows' times comparable: host, CPU model and usable cores (not the load).
    std::string id() const;
    // "node7 (AMD EPYC 7763, 4 of 128 cores)"
    std::string describe() const;
};

// The machine this process runs on now.
MachineInfo currentMachine();

nlohmann::json toJson(const MachineInfo& m);
// Fields that are absent stay empty/zero: rows of older journals have no machine.
MachineInfo machineFromJson(const nlohmann::json& j);

}  // namespace shadowlab::studies
