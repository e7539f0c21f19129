// umbrage.hpp: a header-only C++17 RAII wrapper over umbrage.h (docs/c-api.md). A failed call
// throws umbrage::Error carrying the code and the library's message; the pass is destroyed by
// its owner (move-only). Frames and caster ids stay values, as in C.
#ifndef UMBRAGE_HPP
#define UMBRAGE_HPP

#include <umbrage/umbrage.h>

#include <array>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace umbrage {

/// A failed call: `code()` is the UmbrageResult, `what()` the library's message.
class Error : public std::runtime_error {
public:
    Error(UmbrageResult code, const std::string& call)
        : std::runtime_error(call + ": " + last_message()), code_(code) {}
    UmbrageResult code() const noexcept { return code_; }

    static std::string last_message() {
        std::string s(umbrage_last_error_message(nullptr, 0), '\0');
        if (!s.empty()) umbrage_last_error_message(&s[0], s.size() + 1);
        return s;
    }

private:
    UmbrageResult code_;
};

inline void check(UmbrageResult r, const char* call) {
    if (r != UMBRAGE_SUCCESS) throw Error(r, call);
}

/// A create info with the defaults and this header's ABI version.
inline UmbragePassCreateInfo pass_create_info() {
    UmbragePassCreateInfo info{};
    info.sType = UMBRAGE_STRUCTURE_TYPE_PASS_CREATE_INFO;
    info.abiVersion = UMBRAGE_ABI_VERSION;
    return info;
}

/// Column-major double[16] from a row-major one (idTech-style engines).
inline std::array<double, 16> from_row_major(const double (&m)[16]) {
    std::array<double, 16> out{};
    for (int r = 0; r < 4; ++r)
        for (int c = 0; c < 4; ++c) out[static_cast<size_t>(4 * c + r)] = m[4 * r + c];
    return out;
}

/// The pass: owns an UmbragePass, destroyed with it (after the host's last command buffer that
/// used it has completed).
class Pass {
public:
    Pass(const UmbrageVulkanDevice& vulkan, const UmbragePassCreateInfo& info) {
        check(umbrage_pass_create(&vulkan, &info, &pass_), "umbrage_pass_create");
    }
    ~Pass() { reset(); }
    Pass(const Pass&) = delete;
    Pass& operator=(const Pass&) = delete;
    Pass(Pass&& o) noexcept : pass_(std::exchange(o.pass_, nullptr)) {}
    Pass& operator=(Pass&& o) noexcept {
        if (this != &o) {
            reset();
            pass_ = std::exchange(o.pass_, nullptr);
        }
        return *this;
    }
    void reset() noexcept {
        if (pass_) umbrage_pass_destroy(pass_);
        pass_ = nullptr;
    }
    UmbragePass get() const noexcept { return pass_; }

    UmbrageCapabilities capabilities() const {
        UmbrageCapabilities c{};
        check(umbrage_pass_get_capabilities(pass_, &c), "umbrage_pass_get_capabilities");
        return c;
    }
    UmbragePassSettings settings() const {
        UmbragePassSettings s{};
        check(umbrage_pass_get_settings(pass_, &s), "umbrage_pass_get_settings");
        return s;
    }
    void set_settings(const UmbragePassSettings& s) { check(umbrage_pass_set_settings(pass_, &s), "umbrage_pass_set_settings"); }

    /// An opaque caster from positions (x, y, z a vertex) and 32-bit triangle indices.
    UmbrageCasterId add_caster(const char* name, const std::vector<float>& positions, const std::vector<uint32_t>& indices,
                               const std::array<double, 16>& transform) {
        UmbrageCasterInfo c{};
        c.sType = UMBRAGE_STRUCTURE_TYPE_CASTER_INFO;
        c.pName = name;
        c.pPositions = positions.data();
        c.vertexCount = static_cast<uint32_t>(positions.size() / 3);
        c.pIndices = indices.data();
        c.indexCount = static_cast<uint32_t>(indices.size());
        c.indexType = UMBRAGE_INDEX_TYPE_UINT32;
        for (size_t i = 0; i < 16; ++i) c.transform[i] = transform[i];
        UmbrageCasterId id = 0;
        check(umbrage_pass_add_caster(pass_, &c, &id), "umbrage_pass_add_caster");
        return id;
    }
    void set_transform(UmbrageCasterId id, const std::array<double, 16>& m) {
        check(umbrage_pass_set_caster_transform(pass_, id, m.data()), "umbrage_pass_set_caster_transform");
    }
    void remove_caster(UmbrageCasterId id) { check(umbrage_pass_remove_caster(pass_, id), "umbrage_pass_remove_caster"); }

    UmbrageFrame prepare(uint32_t slot, const UmbrageView& view, const std::vector<UmbrageLight>& lights) {
        UmbrageFrame f{};
        check(umbrage_pass_prepare(pass_, slot, &view, lights.data(), static_cast<uint32_t>(lights.size()), &f), "umbrage_pass_prepare");
        return f;
    }
    UmbrageFrameStats stats(const UmbrageFrame& f) const {
        UmbrageFrameStats s{};
        s.sType = UMBRAGE_STRUCTURE_TYPE_FRAME_STATS;
        check(umbrage_frame_get_stats(pass_, f, &s), "umbrage_frame_get_stats");
        return s;
    }
    UmbrageLightInfo light(const UmbrageFrame& f, uint32_t light) const {
        UmbrageLightInfo l{};
        l.sType = UMBRAGE_STRUCTURE_TYPE_LIGHT_INFO;
        check(umbrage_frame_get_light(pass_, f, light, &l), "umbrage_frame_get_light");
        return l;
    }
    void cmd_before_rendering(VkCommandBuffer cb, const UmbrageFrame& f) {
        check(umbrage_cmd_before_rendering(pass_, cb, f), "umbrage_cmd_before_rendering");
    }
    void cmd_determine(VkCommandBuffer cb, const UmbrageFrame& f, uint32_t light, const UmbrageDepthStencilTarget& t) {
        check(umbrage_cmd_determine(pass_, cb, f, light, &t), "umbrage_cmd_determine");
    }
    void cmd_light_state(VkCommandBuffer cb, const UmbrageFrame& f, uint32_t light, VkExtent2D extent) {
        check(umbrage_cmd_light_state(pass_, cb, f, light, extent), "umbrage_cmd_light_state");
    }

private:
    UmbragePass pass_ = nullptr;
};

}  // namespace umbrage

#endif
