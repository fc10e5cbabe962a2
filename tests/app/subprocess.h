// tests/app/subprocess.h: starts the `shadowlab` program as a child process (output discarded, or
// where the caller puts it) so a test can kill it at a chosen moment, and waits for it.
#pragma once

#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>
#include <functional>
#include <string>
#include <vector>

extern char** environ;

namespace shadowlab::test {

// The child with its standard output and error set up by `redirect` (posix_spawn file actions).
inline pid_t spawnShadowlab(const std::vector<std::string>& args,
                            const std::function<void(posix_spawn_file_actions_t&)>& redirect) {
    std::string exe = SHADOWLAB_EXE;
    std::vector<std::string> copy = args;
    std::vector<char*> argv{exe.data()};
    for (auto& a : copy) argv.push_back(a.data());
    argv.push_back(nullptr);
    posix_spawn_file_actions_t actions;
    posix_spawn_file_actions_init(&actions);
    redirect(actions);
    pid_t pid = -1;
    const int rc = posix_spawn(&pid, exe.c_str(), &actions, nullptr, argv.data(), environ);
    posix_spawn_file_actions_destroy(&actions);
    return rc == 0 ? pid : -1;
}

inline pid_t spawnShadowlab(const std::vector<std::string>& args) {
    return spawnShadowlab(args, [](posix_spawn_file_actions_t& actions) {
        posix_spawn_file_actions_addopen(&actions, 1, "/dev/null", O_WRONLY, 0);
        posix_spawn_file_actions_addopen(&actions, 2, "/dev/null", O_WRONLY, 0);
    });
}

// The child's exit status, or -1 when a signal ended it.
inline int waitFor(pid_t pid) {
    int status = 0;
    waitpid(pid, &status, 0);
    return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

}  // namespace shadowlab::test
