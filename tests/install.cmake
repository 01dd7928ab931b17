# install.cmake -- test_install: install into a temporary prefix and build
# examples/normals.c against it with pkg-config and with find_package.
add_test(NAME test_install
         COMMAND sh ${CMAKE_CURRENT_SOURCE_DIR}/install/test_install.sh
                 ${PROJECT_SOURCE_DIR} ${PROJECT_BINARY_DIR})
set_tests_properties(test_install PROPERTIES LABELS install SKIP_RETURN_CODE 77)
# test_pip: `pip install --no-build-isolation .` in a venv (minutes: slow)
add_test(NAME test_pip
         COMMAND sh ${CMAKE_CURRENT_SOURCE_DIR}/install/test_pip.sh ${PROJECT_SOURCE_DIR}
                 $<TARGET_FILE:jetfit>)
set_tests_properties(test_pip PROPERTIES LABELS "install;slow" SKIP_RETURN_CODE 77 TIMEOUT 1800)
