#include "shader_registry.h"

#include "engine/core/error.h"
#include <string>

namespace nbvh::shaders {

std::span<const uint32_t> find(std::string_view path) {
    for (const detail::Entry* e = detail::TABLE; e->name; ++e)
        if (path == e->name) return {e->words, *e->count};
    throw Error("no embedded shader named '" + std::string(path) + "'");
}

} // namespace nbvh::shaders
