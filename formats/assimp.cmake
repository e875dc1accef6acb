# formats/assimp.cmake — the formats read through Assimp (Debian libassimp-dev 5.2): OBJ + MTL, FBX,
# COLLADA, PLY, STL, 3MF, 3DS, glTF 1.0 and the rest Assimp reads (sy_assimp.h), through its C API.
# Included at the end of formats/CMakeLists.txt.
pkg_check_modules(SY_ASSIMP REQUIRED IMPORTED_TARGET assimp)
target_sources(sy_formats PRIVATE
  sy_assimp.c
  sy_assimp_anim.c
  sy_assimp_io.c
  sy_assimp_isolate.c
  sy_assimp_materials.c
  sy_assimp_scene.c
)
target_link_libraries(sy_formats PRIVATE PkgConfig::SY_ASSIMP)
list(APPEND sy_formats_pkg "SY_ASSIMP|assimp")
