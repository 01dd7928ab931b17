# view.cmake -- `jetfit view` (src/cli/cmd_view.c): its page template
# (src/cli/view/page.html, page.js) becomes C strings in the command,
# regenerated when a template changes, so the build tree and an install
# need no share folder; three.js is read at run time from JF_THREE_DIR
# (Debian's libjs-three; the project ships no copy).
set(JF_THREE_DIR "/usr/share/javascript/three" CACHE PATH
    "three.js for jetfit view (three.min.js and the OrbitControls of its examples)")
set(JF_VIEW_SRC ${PROJECT_BINARY_DIR}/jf_view_template.c)
add_custom_command(OUTPUT ${JF_VIEW_SRC}
  COMMAND ${CMAKE_COMMAND} -DOUT=${JF_VIEW_SRC} -DDIR=${PROJECT_SOURCE_DIR}/src/cli/view
          -P ${PROJECT_SOURCE_DIR}/cmake/embed_view.cmake
  DEPENDS ${PROJECT_SOURCE_DIR}/src/cli/view/page.html ${PROJECT_SOURCE_DIR}/src/cli/view/page.js
          ${PROJECT_SOURCE_DIR}/cmake/embed_view.cmake
  COMMENT "Embedding the jetfit view page")
target_sources(jetfit PRIVATE ${JF_VIEW_SRC})
target_include_directories(jetfit PRIVATE ${PROJECT_SOURCE_DIR}/src/cli)
target_compile_definitions(jetfit PRIVATE JF_THREE_DIR="${JF_THREE_DIR}")
