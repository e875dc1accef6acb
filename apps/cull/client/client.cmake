# apps/cull/client/client.cmake — the three.js page of the culling service (client.html, client.js)
# with three.js vendored from npm into the build tree (no CDN): at build time, where npm is found,
# `npm ci` installs the locked three (package-lock.json) into BUILD/cull_client/npm and vendor.cmake
# copies the files the page imports into BUILD/cull_client/vendor/three/ next to client.html and
# client.js. Without npm the page is not built (a message at configure time); when npm ci fails (no
# network) the build goes on, says so, and the folder has no client.html (delete
# BUILD/cull_client/.stamp to retry). Included by apps/cull/CMakeLists.txt.
#
# For the web server (sy web --client-render serves this folder under /client/):
#   global property SY_CULL_CLIENT_DIR and target property SY_CLIENT_DIR of target sy_cull_client:
#   the folder (absolute); empty when npm is absent. The server checks client.html exists at run time.
set(sy_cull_client_dir ${PROJECT_BINARY_DIR}/cull_client)
find_program(SY_NPM npm)
if(NOT SY_NPM)
  message(STATUS "cull client: npm not found: the three.js page (apps/cull/client) is not built (sy web --client-render will say so)")
  set_property(GLOBAL PROPERTY SY_CULL_CLIENT_DIR "")
  add_custom_target(sy_cull_client)
  set_target_properties(sy_cull_client PROPERTIES SY_CLIENT_DIR "")
  return()
endif()
set(sy_cull_client_src ${CMAKE_CURRENT_LIST_DIR})
add_custom_command(
  OUTPUT ${sy_cull_client_dir}/.stamp
  COMMAND ${CMAKE_COMMAND} -DSRC=${sy_cull_client_src} -DOUT=${sy_cull_client_dir} -DNPM=${SY_NPM}
          -P ${sy_cull_client_src}/vendor.cmake
  DEPENDS ${sy_cull_client_src}/package.json ${sy_cull_client_src}/package-lock.json
          ${sy_cull_client_src}/client.html ${sy_cull_client_src}/client.js ${sy_cull_client_src}/vendor.cmake
  COMMENT "cull client: npm ci (three.js) and vendoring into ${sy_cull_client_dir}"
  VERBATIM)
add_custom_target(sy_cull_client ALL DEPENDS ${sy_cull_client_dir}/.stamp)
set_property(GLOBAL PROPERTY SY_CULL_CLIENT_DIR ${sy_cull_client_dir})
set_target_properties(sy_cull_client PROPERTIES SY_CLIENT_DIR ${sy_cull_client_dir})
