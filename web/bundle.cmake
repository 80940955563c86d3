# Bundles the dashboard page: cmake -DSRC=web -DOUT=BUILD/web -DNPM=npm -P bundle.cmake
# npm ci installs the locked chart.js and esbuild into OUT/node_modules (install scripts not run), esbuild bundles
# src/main.js into OUT/dist/app.js next to index.html. Without the npm registry the page is left out with a warning
# (canyon-dashboard then serves a page saying so, and the browser test skips); an esbuild error fails the build.
file(MAKE_DIRECTORY ${OUT})
file(COPY ${SRC}/package.json ${SRC}/package-lock.json DESTINATION ${OUT})
if(NOT EXISTS ${OUT}/node_modules/.package-lock.json OR ${SRC}/package-lock.json IS_NEWER_THAN
                                                         ${OUT}/node_modules/.package-lock.json)
  execute_process(COMMAND ${NPM} ci --no-audit --no-fund --ignore-scripts --loglevel=error WORKING_DIRECTORY ${OUT}
                  RESULT_VARIABLE rc)
  if(NOT rc EQUAL 0)
    message(WARNING "dashboard page not bundled: npm ci failed (is the npm registry reachable?)")
    file(REMOVE ${OUT}/dist/app.js ${OUT}/dist/index.html)
    file(TOUCH ${OUT}/bundle.stamp)
    return()
  endif()
endif()
file(REMOVE_RECURSE ${OUT}/src)
file(COPY ${SRC}/src DESTINATION ${OUT})
execute_process(COMMAND ${OUT}/node_modules/.bin/esbuild src/main.js --bundle --minify --target=es2020
                        --log-level=warning --outfile=dist/app.js WORKING_DIRECTORY ${OUT} RESULT_VARIABLE rc)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "esbuild could not bundle web/src/main.js")
endif()
file(COPY ${SRC}/index.html DESTINATION ${OUT}/dist)
file(TOUCH ${OUT}/bundle.stamp)
