#include "app/output_path.h"

#include <unistd.h>

#include <filesystem>
#include <fstream>

#include "engine/core/error.h"
#include "engine/core/log.h"

namespace nbvh::app {
namespace fs = std::filesystem;

void check_output_path(const std::string& out, const char* option, const std::vector<std::string>& inputs) {
    if (out.empty()) return;
    std::error_code ec;
    if (fs::is_directory(out, ec))
        throw Error(strfmt("%s '%s' is a directory; give a file name", option, out.c_str()));
    fs::path dir = fs::path(out).parent_path();
    if (dir.empty()) dir = ".";
    if (!fs::is_directory(dir, ec))
        throw Error(strfmt("%s '%s': directory '%s' does not exist", option, out.c_str(), dir.string().c_str()));
    if (!fs::exists(out, ec)) return;
    for (const std::string& in : inputs) {
        if (in.empty() || !fs::exists(in, ec)) continue;
        if (fs::equivalent(out, in, ec) && !ec)
            throw Error(strfmt("%s '%s' is the input file '%s'; refusing to overwrite it", option, out.c_str(),
                               in.c_str()));
    }
}

void write_text_atomically(const std::string& path, const std::string& text) {
    const std::string tmp = path + strfmt(".tmp%ld", long(::getpid()));
    std::error_code ec;
    {
        std::ofstream f(tmp, std::ios::binary | std::ios::trunc);
        if (!f) throw Error(strfmt("cannot write '%s'", path.c_str()));
        f << text;
        f.flush();
        if (!f) {
            f.close();
            fs::remove(tmp, ec);
            throw Error(strfmt("cannot write '%s' (disk full?)", path.c_str()));
        }
    }
    fs::rename(tmp, path, ec);
    if (ec) {
        fs::remove(tmp, ec);
        throw Error(strfmt("cannot write '%s': %s", path.c_str(), ec.message().c_str()));
    }
}

} // namespace nbvh::app
