#include "shader_registry.h"

#include "engine/core/error.h"
#include <string>

namespace nbvh::shaders {

std::span<const uint32_t> find(std::string_view path) {
    for (const detail::Entry* e = detail::TABLE; e->name; ++e)
        if (path == e->name) return {e->words, *e->count};
    throw Error("no embedded shader named '" + std::string(path) + "'");
}

bool contains(std::string_view path) {
    for (const detail::Entry* e = detail::TABLE; e->name; ++e)
        if (path == e->name) return true;
    return false;
}

std::string variant(std::string_view path, std::string_view variant) {
    std::string name = std::string(path) + "#" + std::string(variant);
    return contains(name) ? name : std::string(path);
}

std::vector<std::string_view> names() {
    std::vector<std::string_view> out;
    for (const detail::Entry* e = detail::TABLE; e->name; ++e) out.push_back(e->name);
    return out;
}

} // namespace nbvh::shaders
