# nbvh_library(NAME DIR [DEPS ...]): a static library from every .cpp in DIR (one library per engine
# folder, so each folder builds and is tested on its own).
function(nbvh_library name dir)
  file(GLOB srcs CONFIGURE_DEPENDS ${dir}/*.cpp)
  add_library(${name} STATIC ${srcs})
  target_include_directories(${name} PUBLIC ${PROJECT_SOURCE_DIR})
  target_link_libraries(${name} PUBLIC nbvh::deps ${ARGN})
endfunction()

# nbvh_test(NAME LABELS "a;b" SOURCES ... DEPS ...): one GoogleTest executable registered with CTest.
# Tests run from the build tree; NBVH_SHARED_DIR points at ../shared when present (tests skip without).
function(nbvh_test name)
  cmake_parse_arguments(T "" "TIMEOUT" "LABELS;SOURCES;DEPS" ${ARGN})
  add_executable(${name} ${T_SOURCES})
  target_link_libraries(${name} PRIVATE ${T_DEPS} nbvh_test_support GTest::gtest GTest::gtest_main)
  if(NOT T_TIMEOUT)
    set(T_TIMEOUT 600)
  endif()
  gtest_discover_tests(${name} DISCOVERY_TIMEOUT 60
                       PROPERTIES LABELS "${T_LABELS}" TIMEOUT ${T_TIMEOUT} SKIP_RETURN_CODE 77)
endfunction()
