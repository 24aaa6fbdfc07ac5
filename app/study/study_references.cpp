#include "app/study/study_references.h"

#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "app/output_path.h"
#include "engine/core/error.h"
#include "engine/core/log.h"

namespace nbvh::app::study {

namespace fs = std::filesystem;

namespace {

constexpr int FORMAT = 1;

fs::path file_of(const std::string& dir, size_t index, const char* suffix) {
    return fs::path(dir) / strfmt("camera_%zu%s", index, suffix);
}

// The pixels of `png` as the FLIPs see them; a file of another size than `like` is refused.
Image load_pixels(const fs::path& png, const Image* like) {
    Image img = load_image(png.string()); // 8-bit sRGB decoded with the exact curve: as_png_pixels' values
    if (like && (img.width != like->width || img.height != like->height))
        throw Error(strfmt("--references: %s is %dx%d, not %dx%d", png.string().c_str(), img.width,
                           img.height, like->width, like->height));
    return img;
}

void save_pixels(const fs::path& png, const Image& px) {
    const std::string tmp = png.string() + strfmt(".tmp%ld.png", long(::getpid()));
    save_png(tmp, px); // linear [0,1] in, the same 8-bit sRGB values out (clamp, no exposure)
    std::error_code ec;
    fs::rename(tmp, png, ec);
    if (ec) {
        fs::remove(tmp, ec);
        throw Error(strfmt("cannot write '%s'", png.string().c_str()));
    }
}

// The first field (in `expected`'s order) whose value differs in `found`, or "" when none does.
std::string first_difference(const nlohmann::json& expected, const nlohmann::json& found) {
    for (auto it = expected.begin(); it != expected.end(); ++it) {
        if (!found.is_object() || !found.contains(it.key())) return it.key();
        if (found.at(it.key()) != it.value()) return it.key();
    }
    return {};
}

} // namespace

std::optional<CachedCamera> load_reference(const std::string& dir, size_t index, const nlohmann::json& key) {
    const fs::path meta = file_of(dir, index, ".json");
    if (!fs::exists(meta)) return std::nullopt;
    nlohmann::json j;
    try {
        std::ifstream f(meta);
        std::stringstream text;
        text << f.rdbuf();
        j = nlohmann::json::parse(text.str());
        if (j.value("format", 0) != FORMAT) throw Error("format");
    } catch (const std::exception&) {
        throw Error(strfmt("--references: %s is not a reference of this nbvh version (delete the folder's "
                           "camera_%zu files, or use another folder)",
                           meta.string().c_str(), index));
    }
    const std::string diff = first_difference(key, j.value("key", nlohmann::json::object()));
    if (!diff.empty()) {
        const nlohmann::json& found = j["key"];
        throw Error(strfmt(
            "--references %s: camera %zu there was made with %s %s, this study has %s (use another "
            "folder)",
            dir.c_str(), index, diff.c_str(), found.contains(diff) ? found.at(diff).dump().c_str() : "(none)",
            key.at(diff).dump().c_str()));
    }
    CachedCamera c;
    try {
        c.exposure = j.at("exposure_stops").get<float>();
        c.noise_floor = j.at("noise_floor").get<double>();
        c.classical_ms = j.at("classical_frame_ms").get<double>();
        for (const auto& e : j.at("equal_time_flip"))
            c.equal_time_flip[e.at("spp").get<uint32_t>()] = e.at("flip").get<double>();
    } catch (const nlohmann::json::exception&) {
        throw Error(strfmt("--references: %s lacks a figure (delete it, or use another folder)",
                           meta.string().c_str()));
    }
    if (!std::isfinite(c.noise_floor) || !std::isfinite(c.classical_ms) || !std::isfinite(c.exposure))
        throw Error(strfmt("--references: %s holds a non-finite figure", meta.string().c_str()));
    c.reference_px = load_pixels(file_of(dir, index, "_reference.png"), nullptr);
    c.floor_px = load_pixels(file_of(dir, index, "_floor.png"), &c.reference_px);
    return c;
}

void save_reference(const std::string& dir, size_t index, const nlohmann::json& key, const CachedCamera& c) {
    std::error_code ec;
    fs::create_directories(dir, ec);
    if (ec) throw Error(strfmt("--references: cannot create '%s': %s", dir.c_str(), ec.message().c_str()));
    save_pixels(file_of(dir, index, "_reference.png"), c.reference_px);
    save_pixels(file_of(dir, index, "_floor.png"), c.floor_px);
    nlohmann::json et = nlohmann::json::array();
    for (const auto& [spp, flip] : c.equal_time_flip) et.push_back({{"spp", spp}, {"flip", flip}});
    const nlohmann::json j = {{"format", FORMAT},
                              {"key", key},
                              {"exposure_stops", c.exposure},
                              {"noise_floor", c.noise_floor},
                              {"classical_frame_ms", c.classical_ms},
                              {"equal_time_flip", et}};
    // The figures last: a reader that finds the JSON finds the images it names.
    write_text_atomically(file_of(dir, index, ".json").string(), j.dump(1) + "\n");
}

} // namespace nbvh::app::study
