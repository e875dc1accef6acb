# apps/cull/client/vendor.cmake — cmake -P script run at build time by client.cmake:
#   -DSRC=apps/cull/client -DOUT=BUILD/cull_client -DNPM=/usr/bin/npm
# npm ci (the locked three.js) into OUT/npm, then copies client.html, client.js and the three.js
# files the page imports into OUT (vendor/three/...). A failed npm ci is not a build failure: the
# page is left out (no OUT/client.html) and the reason printed. OUT/.stamp is written either way.
file(MAKE_DIRECTORY ${OUT}/npm)
file(REMOVE ${OUT}/client.html ${OUT}/client.js)
file(REMOVE_RECURSE ${OUT}/vendor)
configure_file(${SRC}/package.json ${OUT}/npm/package.json COPYONLY)
configure_file(${SRC}/package-lock.json ${OUT}/npm/package-lock.json COPYONLY)
execute_process(COMMAND ${NPM} ci --prefer-offline --no-audit --no-fund --ignore-scripts --loglevel=error
                WORKING_DIRECTORY ${OUT}/npm RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE out
                TIMEOUT 300)
set(three ${OUT}/npm/node_modules/three)
set(files build/three.module.js build/three.core.js examples/jsm/loaders/GLTFLoader.js
          examples/jsm/utils/BufferGeometryUtils.js examples/jsm/utils/SkeletonUtils.js
          examples/jsm/controls/OrbitControls.js examples/jsm/libs/meshopt_decoder.module.js
          examples/jsm/environments/RoomEnvironment.js LICENSE)
set(missing)
if(rc EQUAL 0)
  foreach(f ${files})
    if(NOT EXISTS ${three}/${f})
      list(APPEND missing ${f})
    endif()
  endforeach()
endif()
if(NOT rc EQUAL 0 OR missing)
  string(STRIP "${out}" out)
  message(WARNING "cull client: skipped, the three.js page is absent from ${OUT}: "
                  "npm ci failed (${rc}; no network or registry?) ${out} ${missing}")
  file(TOUCH ${OUT}/.stamp)
  return()
endif()
foreach(f ${files})
  get_filename_component(d ${f} DIRECTORY)
  file(COPY ${three}/${f} DESTINATION ${OUT}/vendor/three/${d})
endforeach()
file(COPY ${SRC}/client.js ${SRC}/client.html DESTINATION ${OUT})
file(TOUCH ${OUT}/.stamp)
message(STATUS "cull client: three.js vendored into ${OUT}/vendor/three")
