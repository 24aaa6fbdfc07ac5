# Every dependency is a Debian 12 package (see README.md here); this file only finds them and
# gives each one target name. Included from the top-level CMakeLists.txt.. No third-party source lives in this repository.
find_package(Vulkan REQUIRED)
find_package(glm REQUIRED)
find_package(TinyGLTF REQUIRED)
find_package(tinyexr REQUIRED)
find_package(nlohmann_json REQUIRED)
find_package(CLI11 REQUIRED)
find_package(meshoptimizer REQUIRED)
find_package(Threads REQUIRED)
find_program(NBVH_GLSLC glslc REQUIRED)

add_library(nbvh_deps INTERFACE)
add_library(nbvh::deps ALIAS nbvh_deps)
target_link_libraries(nbvh_deps INTERFACE Vulkan::Vulkan glm::glm Threads::Threads)

# tinygltf (Debian ships a shared library with stb_image compiled in)
add_library(nbvh_tinygltf INTERFACE)
add_library(nbvh::tinygltf ALIAS nbvh_tinygltf)
target_link_libraries(nbvh_tinygltf INTERFACE TinyGLTF::TinyGLTF)

# meshoptimizer (shared library): mesh simplification, the equal-memory baseline of nbvh study
add_library(nbvh_meshoptimizer INTERFACE)
add_library(nbvh::meshoptimizer ALIAS nbvh_meshoptimizer)
target_link_libraries(nbvh_meshoptimizer INTERFACE meshoptimizer::meshoptimizer)

# tinyexr (shared library)
add_library(nbvh_tinyexr INTERFACE)
add_library(nbvh::tinyexr ALIAS nbvh_tinyexr)
target_link_libraries(nbvh_tinyexr INTERFACE tinyexr::tinyexr)

# stb (libstb-dev: headers + libstb)
add_library(nbvh_stb INTERFACE)
add_library(nbvh::stb ALIAS nbvh_stb)
target_include_directories(nbvh_stb INTERFACE /usr/include/stb)
target_link_libraries(nbvh_stb INTERFACE stb)

if(NBVH_BUILD_TESTS)  # (included from the top level so imported targets are global)
  find_package(GTest REQUIRED)
endif()

# GLFW + Dear ImGui (the interactive viewer, app/viewer/). Debian's libimgui-dev ships a static
# libimgui.a with the GLFW and Vulkan backends compiled in and headers under /usr/include/imgui
# (backends/ beside them); it needs libstb (stb_truetype) and GLFW at link time.
find_package(glfw3 3.3 REQUIRED)
find_library(NBVH_IMGUI_LIBRARY imgui REQUIRED)
find_path(NBVH_IMGUI_INCLUDE_DIR imgui.h PATHS /usr/include/imgui REQUIRED)
add_library(nbvh_imgui INTERFACE)
add_library(nbvh::imgui ALIAS nbvh_imgui)
target_include_directories(nbvh_imgui INTERFACE ${NBVH_IMGUI_INCLUDE_DIR} ${NBVH_IMGUI_INCLUDE_DIR}/backends)
target_link_libraries(nbvh_imgui INTERFACE ${NBVH_IMGUI_LIBRARY} glfw nbvh::stb Vulkan::Vulkan)
