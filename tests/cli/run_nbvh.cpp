#include "tests/cli/run_nbvh.h"

#include <fcntl.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstring>
#include <fstream>
#include <sstream>
#include <thread>

#include <gtest/gtest.h>

#include "tests/support/test_support.h"

namespace nbvh::test {
namespace fs = std::filesystem;

fs::path nbvh_exe() { return NBVH_EXE; }

namespace {
std::string read_all(const fs::path& p) {
    std::ifstream f(p, std::ios::binary);
    std::stringstream s;
    s << f.rdbuf();
    return s.str();
}
} // namespace

RunResult run_nbvh(const std::vector<std::string>& args, double timeout_s, const fs::path& cwd) {
    return run_command(nbvh_exe(), args, timeout_s, cwd);
}

RunResult run_command(const fs::path& exe, const std::vector<std::string>& args, double timeout_s,
                      const fs::path& cwd) {
    // Output goes to files (not pipes) so a chatty child never blocks on a full pipe.
    static int counter = 0;
    const fs::path dir = fs::path(NBVH_BINARY_DIR) / "test_tmp" / "cli_capture";
    fs::create_directories(dir);
    const std::string tag = std::to_string(getpid()) + "_" + std::to_string(counter++);
    const fs::path out_path = dir / ("out_" + tag), err_path = dir / ("err_" + tag);

    std::vector<std::string> argv_s = {exe.string()};
    argv_s.insert(argv_s.end(), args.begin(), args.end());
    std::vector<char*> argv;
    for (std::string& s : argv_s) argv.push_back(s.data());
    argv.push_back(nullptr);

    RunResult r;
    const pid_t pid = fork();
    if (pid < 0) {
        r.err = std::string("fork failed: ") + std::strerror(errno);
        return r;
    }
    if (pid == 0) {
        const int fo = open(out_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
        const int fe = open(err_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
        const int fi = open("/dev/null", O_RDONLY);
        if (fo < 0 || fe < 0 || fi < 0) _exit(126);
        dup2(fi, 0);
        dup2(fo, 1);
        dup2(fe, 2);
        if (!cwd.empty() && chdir(cwd.c_str()) != 0) _exit(126);
        execv(argv[0], argv.data());
        _exit(127);
    }
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_s);
    int status = 0;
    for (;;) {
        const pid_t w = waitpid(pid, &status, WNOHANG);
        if (w == pid) break;
        if (std::chrono::steady_clock::now() > deadline) {
            kill(pid, SIGKILL);
            waitpid(pid, &status, 0);
            r.timed_out = true;
            break;
        }
        std::this_thread::sleep_for(std::chrono::milliseconds(5));
    }
    if (!r.timed_out) {
        if (WIFSIGNALED(status)) {
            r.signaled = true;
            r.signal = WTERMSIG(status);
        } else if (WIFEXITED(status)) {
            r.exit_code = WEXITSTATUS(status);
        }
    }
    r.out = read_all(out_path);
    r.err = read_all(err_path);
    fs::remove(out_path);
    fs::remove(err_path);
    return r;
}

std::string RunResult::describe() const {
    std::ostringstream s;
    if (timed_out) s << "TIMED OUT";
    else if (signaled) s << "killed by signal " << signal << " (" << strsignal(signal) << ")";
    else s << "exit code " << exit_code;
    s << "\n--- stderr ---\n" << err << "--- stdout ---\n" << out.substr(0, 2000) << "---";
    return s.str();
}

std::vector<std::string> split_lines(const std::string& text) {
    std::vector<std::string> lines;
    std::istringstream s(text);
    for (std::string line; std::getline(s, line);) lines.push_back(line);
    return lines;
}

std::string check_clean_error(const RunResult& r, const std::vector<std::string>& must_mention, bool strict) {
    if (r.timed_out) return "timed out (hang?)";
    if (r.signaled) return std::string("killed by signal ") + strsignal(r.signal) + " (crash/abort)";
    if (r.exit_code == 0) return "exit code 0, expected a failure";
    const std::vector<std::string> lines = split_lines(r.err);
    if (lines.empty()) return "nothing on stderr";
    const std::string prefix = "nbvh: error: ";
    int errors = 0;
    for (size_t i = 0; i < lines.size(); ++i) {
        const std::string& l = lines[i];
        if (l.rfind(prefix, 0) == 0) {
            ++errors;
            if (i + 1 != lines.size()) return "the error line is not the last line of stderr";
            if (l.size() <= prefix.size() + 3) return "error message is empty";
        } else if (l.rfind("warning: ", 0) == 0) {
            continue;
        } else if (!strict && l.find("error") == std::string::npos && l.find("terminate") == std::string::npos &&
                   l.find("abort") == std::string::npos && l.find("Abort") == std::string::npos &&
                   l.find("fault") == std::string::npos && l.find("what()") == std::string::npos) {
            continue; // an informational line
        } else {
            return "stderr line " + std::to_string(i + 1) + " is neither 'warning: ...' nor 'nbvh: error: ...': '" +
                   l + "'";
        }
    }
    if (errors != 1) return "expected exactly one 'nbvh: error: ' line";
    for (const std::string& w : must_mention)
        if (lines.back().find(w) == std::string::npos) return "error line does not mention '" + w + "'";
    return "";
}

const fs::path& tiny_default_model(const std::string& prefix) {
    static const fs::path model = [&] {
        const fs::path m = temp_dir(prefix + "_" + std::to_string(::getpid())) / "tiny.nbvh";
        const RunResult r = run_nbvh({"train", "default", "--backend", "cpu", "--steps", "20", "--batch", "256",
                                      "--nodes", "63", "--hash-log2", "12", "--lods", "2", "--threads", "2", "--out",
                                      m.string()},
                                     120.0);
        EXPECT_EQ(r.exit_code, 0) << r.describe();
        return m;
    }();
    return model;
}

} // namespace nbvh::test
