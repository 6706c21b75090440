# cmake -DSRC=<web/> -DDST=<build>/web -P copy_assets.cmake
# Copies the page (web/src) and the three.js modules it imports into the web root.
# file(COPY) keeps timestamps and skips files that are already up to date.

file(COPY ${SRC}/src/ DESTINATION ${DST})

set(three ${SRC}/node_modules/three)
if(NOT EXISTS ${three}/build/three.module.js)
  message(WARNING "web/node_modules/three is missing: run `npm ci` in web/ (scripts/setup.sh does); "
                  "until then the page's 3D view cannot load.")
  return()
endif()
# three.module.js imports ./three.core.js; OrbitControls imports 'three' (the page's import map).
file(COPY ${three}/build/three.module.js ${three}/build/three.core.js ${three}/LICENSE
     DESTINATION ${DST}/vendor/three)
file(COPY ${three}/examples/jsm/controls/OrbitControls.js DESTINATION ${DST}/vendor/three/addons/controls)
