# install.cmake -- test_install: install into a temporary prefix and build
# examples/normals.c against it with pkg-config and with find_package.
add_test(NAME test_install
         COMMAND sh ${CMAKE_CURRENT_SOURCE_DIR}/install/test_install.sh
                 ${PROJECT_SOURCE_DIR} ${PROJECT_BINARY_DIR})
set_tests_properties(test_install PROPERTIES LABELS install SKIP_RETURN_CODE 77)
