// tools/common/spawn.hpp: start a helper program (gnuplot, a probe) from an argument vector.
//
// What it is: fork + execvp with the arguments passed through unchanged, so a
// path or a name can never be read as shell syntax (quotes, ';', '$(...)'
// stay bytes of one argument). Optionally a working folder, extra
// environment entries, and the child's stdout+stderr captured or silenced.
// What it does not do: run shell command lines (there is deliberately no way
// to), time limits, or stdin (the child gets /dev/null).
//
//   auto r = cli::spawn({.argv = {"gnuplot", "accuracy.gp"}, .workingDir = outDir});
//   if (!r.started) fail(r.error);              // e.g. gnuplot is not installed
//   else if (r.exitCode != 0) fail("gnuplot failed");
//
// Threading: may be called from any thread; the child only calls
// async-signal-safe functions between fork and exec.
#pragma once

#include <cerrno>
#include <cstring>
#include <fcntl.h>
#include <string>
#include <sys/wait.h>
#include <unistd.h>
#include <vector>

extern char** environ;

namespace cli {

enum class ChildOutput {
    Inherit, // the child writes to this process's stdout and stderr (default)
    Capture, // stdout and stderr together into SpawnResult::output
    Discard, // both to /dev/null
};

struct SpawnDesc {
    std::vector<std::string> argv{};           // argv[0] is looked up in PATH (execvp); required, non-empty
    std::string workingDir{};                  // default "": this process's working folder
    std::vector<std::string> env{};            // default none: NAME=VALUE entries added to (or replacing in) this environment
    ChildOutput output = ChildOutput::Inherit; // default Inherit
};

struct SpawnResult {
    bool started = false; // false: the program could not be started (see error); exitCode is then meaningless
    int exitCode = -1;    // the child's exit status; 128 + N when killed by signal N
    std::string output;   // with ChildOutput::Capture
    std::string error;    // why it did not start, naming the program
};

inline SpawnResult spawn(const SpawnDesc& d) {
    SpawnResult r;
    if (d.argv.empty()) {
        r.error = "spawn: no program given";
        return r;
    }
    // Everything the child needs is built before fork: after it only
    // async-signal-safe calls are allowed (the parent may have threads).
    std::vector<char*> args;
    for (const std::string& a : d.argv) args.push_back(const_cast<char*>(a.c_str()));
    args.push_back(nullptr);
    std::vector<std::string> envStore;
    for (char** e = environ; e && *e; ++e) {
        const std::string entry = *e;
        bool replaced = false;
        for (const std::string& add : d.env) {
            const size_t eq = add.find('=');
            if (eq != std::string::npos && entry.compare(0, eq + 1, add, 0, eq + 1) == 0) replaced = true;
        }
        if (!replaced) envStore.push_back(entry);
    }
    for (const std::string& add : d.env) envStore.push_back(add);
    std::vector<char*> envp;
    for (const std::string& e : envStore) envp.push_back(const_cast<char*>(e.c_str()));
    envp.push_back(nullptr);

    int status[2]; // the child writes errno here if exec fails; closed on a successful exec
    int capture[2] = {-1, -1};
    if (pipe2(status, O_CLOEXEC) != 0) {
        r.error = "spawn: " + d.argv[0] + ": pipe: " + std::strerror(errno);
        return r;
    }
    if (d.output == ChildOutput::Capture && pipe2(capture, O_CLOEXEC) != 0) {
        r.error = "spawn: " + d.argv[0] + ": pipe: " + std::strerror(errno);
        close(status[0]);
        close(status[1]);
        return r;
    }
    const pid_t pid = fork();
    if (pid < 0) {
        r.error = "spawn: " + d.argv[0] + ": fork: " + std::strerror(errno);
        close(status[0]);
        close(status[1]);
        if (capture[0] >= 0) close(capture[0]), close(capture[1]);
        return r;
    }
    if (pid == 0) {
        auto die = [&](int stage) {
            const int err[2] = {stage, errno};
            [[maybe_unused]] ssize_t n = write(status[1], err, sizeof err);
            _exit(127);
        };
        const int devNull = open("/dev/null", O_RDWR);
        if (devNull >= 0) dup2(devNull, STDIN_FILENO);
        if (d.output == ChildOutput::Capture) {
            dup2(capture[1], STDOUT_FILENO);
            dup2(capture[1], STDERR_FILENO);
        } else if (d.output == ChildOutput::Discard && devNull >= 0) {
            dup2(devNull, STDOUT_FILENO);
            dup2(devNull, STDERR_FILENO);
        }
        if (!d.workingDir.empty() && chdir(d.workingDir.c_str()) != 0) die(1);
        execvpe(args[0], args.data(), envp.data());
        die(2);
    }
    close(status[1]);
    if (capture[1] >= 0) {
        close(capture[1]);
        char buf[4096];
        for (;;) {
            const ssize_t n = read(capture[0], buf, sizeof buf);
            if (n > 0) r.output.append(buf, size_t(n));
            else if (n == 0 || errno != EINTR) break;
        }
        close(capture[0]);
    }
    int err[2] = {0, 0};
    ssize_t got = 0;
    do got = read(status[0], err, sizeof err);
    while (got < 0 && errno == EINTR);
    close(status[0]);
    int ws = 0;
    while (waitpid(pid, &ws, 0) < 0 && errno == EINTR) {}
    if (got == ssize_t(sizeof err)) {
        r.error = err[0] == 1 ? "cannot enter folder '" + d.workingDir + "' to run " + d.argv[0] + ": " + std::strerror(err[1])
                              : "cannot run '" + d.argv[0] + "': " + std::strerror(err[1]);
        return r;
    }
    r.started = true;
    r.exitCode = WIFEXITED(ws) ? WEXITSTATUS(ws) : WIFSIGNALED(ws) ? 128 + WTERMSIG(ws) : -1;
    return r;
}

} // namespace cli
