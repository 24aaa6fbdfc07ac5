#include "app/viewer/film_stage.h"

#include <algorithm>
#include <cstring>

#include "engine/core/error.h"

namespace nbvh::viewer {

FilmStage::FilmStage(const vk::Context& ctx, bool srgb)
    : ctx_(ctx), srgb_(srgb), display_(ctx), display_right_(ctx) {}

void FilmStage::ensure_size(uint32_t width, uint32_t height) {
    if (image_ && image_.width() == width && image_.height() == height) return;
    // Only copied into and blitted from (every Image is a transfer source and destination).
    image_ = vk::Image(ctx_, width, height, srgb_ ? vk::ImageFormat::rgba8_srgb : vk::ImageFormat::rgba8,
                       vk::image_sampled, "viewer film");
    packed_ = vk::Buffer(ctx_, uint64_t(width) * height * 4, vk::MemoryKind::device, 0, "viewer film bytes");
    packed_right_ = vk::Buffer();
    upload_ = vk::Buffer();
}

const vk::Image& FilmStage::record(vk::CommandBuffer& cmd, const FilmSource& film) {
    NBVH_CHECK(film.linear && film.width > 0 && film.height > 0 &&
               film.linear->size() >= uint64_t(film.width) * film.height * 16u);
    const uint32_t width = film.width, height = film.height;
    ensure_size(width, height);
    const uint64_t bytes = uint64_t(width) * height * 4;
    if (film.rgba8) {
        // Host bytes: this slot's previous frame is done (its fence), so the mapped buffer is free.
        NBVH_CHECK(film.rgba8->size() == size_t(width) * height);
        if (!upload_) upload_ = vk::Buffer(ctx_, bytes, vk::MemoryKind::host, 0, "viewer host bytes");
        std::memcpy(upload_.mapped(), film.rgba8->data(), bytes);
        cmd.copy_to_image(upload_, 0, width, image_, 0, 0, width, height);
    } else {
        // Columns [0, split) from the left film's bytes, [split, width) from the right one's.
        const uint32_t split = film.linear_right ? std::min(film.split_column, width) : width;
        display_.record(cmd, *film.linear, packed_, width * height, film.exposure, film.tone_map);
        if (split < width) {
            if (!packed_right_)
                packed_right_ = vk::Buffer(ctx_, bytes, vk::MemoryKind::device, 0, "viewer right film bytes");
            display_right_.record(cmd, *film.linear_right, packed_right_, width * height, film.exposure,
                                  film.tone_map);
        }
        cmd.copy_to_image(packed_, 0, width, image_, 0, 0, split, height);
        if (split < width) cmd.copy_to_image(packed_right_, uint64_t(split) * 4, width, image_, split, 0, width - split, height);
    }
    cmd.barrier(vk::Barrier::transfer_to_transfer);
    return image_;
}

} // namespace nbvh::viewer
