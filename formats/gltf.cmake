# formats/gltf.cmake — the glTF 2.0 loader in sy_formats: a C loader (sy_gltf.c and its modules,
# sy_gltf_internal.h) over a small C++17 shim around tinygltf (sy_gltf_shim.cpp, its writer half
# sy_gltf_shim_write.cpp and the Draco decoder sy_gltf_draco.cpp, the only C++ in
# formats/). Included at the end of formats/CMakeLists.txt.
target_sources(sy_formats PRIVATE
  sy_gltf.c
  sy_gltf_errors.c
  sy_gltf_validate.c
  sy_gltf_accessors.c
  sy_gltf_materials.c
  sy_gltf_meshes.c
  sy_gltf_nodes.c
  sy_gltf_animations.c
  sy_gltf_variants.c
  sy_gltf_shim.cpp
  sy_gltf_shim_write.cpp
  sy_gltf_draco.cpp
  sy_gltf_meshopt.c
)
# Debian's tinygltf exports TinyGLTF::TinyGLTF; accept the lower-case spelling too.
if(TARGET TinyGLTF::tinygltf)
  set(SY_TINYGLTF_TARGET TinyGLTF::tinygltf)
else()
  set(SY_TINYGLTF_TARGET TinyGLTF::TinyGLTF)
endif()
# stb_image: the shim decodes images itself (dimension limit before allocation).
pkg_check_modules(SY_STB REQUIRED IMPORTED_TARGET stb)
target_link_libraries(sy_formats PRIVATE ${SY_TINYGLTF_TARGET} PkgConfig::SY_STB) # Debian builds stb as libstb
# KHR_draco_mesh_compression: Debian's libdraco-dev (sy_gltf_draco.cpp, called by the shim).
# Debian's libdraco.so carries and exports its own tinygltf (351 tinygltf:: symbols, built with
# other options): it must come after libtinygltf in every link line, or tinygltf's calls bind to
# draco's copy and crash (free(): invalid pointer in ~TinyGLTF, seen in the pkg-config consumer of
# install_consumer). Linked here after TinyGLTF, and for pkg-config as a Requires.private module
# listed after tinygltf (sy_formats_pkg), never in Libs.private ahead of it.
pkg_check_modules(SY_DRACO REQUIRED IMPORTED_TARGET draco)
target_link_libraries(sy_formats PRIVATE PkgConfig::SY_DRACO)
list(APPEND sy_formats_pkg "SY_DRACO|draco")
# EXT_meshopt_compression: meshoptimizer's decoders (libmeshoptimizer-dev, sy_gltf_meshopt.c).
find_package(meshoptimizer REQUIRED)
target_link_libraries(sy_formats PRIVATE meshoptimizer::meshoptimizer)
# EXT_texture_webp: Debian's libwebp-dev (WebPGetInfo, then WebPDecodeRGBAInto in the shim's image callback).
pkg_check_modules(SY_WEBP REQUIRED IMPORTED_TARGET libwebp)
target_link_libraries(sy_formats PRIVATE PkgConfig::SY_WEBP)
list(APPEND sy_formats_pkg "SY_WEBP|libwebp")
