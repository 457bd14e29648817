# One interface target carries the project's warning policy; every eical target links it.
add_library(eical_warnings INTERFACE)
target_compile_options(eical_warnings INTERFACE
  $<$<COMPILE_LANGUAGE:CXX>:-Wall -Wextra -Wpedantic -Wshadow -Wnon-virtual-dtor
    -Wold-style-cast -Wcast-align -Woverloaded-virtual -Wconversion -Wno-sign-conversion
    -Wdouble-promotion -Wimplicit-fallthrough>)
if(EICAL_WERROR)
  target_compile_options(eical_warnings INTERFACE $<$<COMPILE_LANGUAGE:CXX>:-Werror>)
endif()

# Helper: a folder is one static library; its sources are the .cpp files below it
# (executables' main files excluded). Folders are small, one idea per file, so globbing
# keeps CMake out of every change. Includes are rooted at the repository: "dsp/frame.hpp".
function(eical_folder_library name dir)
  file(GLOB_RECURSE _srcs CONFIGURE_DEPENDS ${dir}/*.cpp)
  list(FILTER _srcs EXCLUDE REGEX ".*_main\\.cpp$")
  # A subfolder with its own CMakeLists.txt is a library of its own (e.g. drivers/dds).
  file(GLOB _subdirs LIST_DIRECTORIES true ${dir}/*)
  foreach(_sub ${_subdirs})
    if(IS_DIRECTORY ${_sub} AND EXISTS ${_sub}/CMakeLists.txt)
      list(FILTER _srcs EXCLUDE REGEX "^${_sub}/.*")
    endif()
  endforeach()
  add_library(${name} STATIC ${_srcs})
  if(EICAL_UNITY_LIBS)
    set_target_properties(${name} PROPERTIES UNITY_BUILD ON)
  endif()
  target_include_directories(${name} PUBLIC ${PROJECT_SOURCE_DIR})
  target_link_libraries(${name} PRIVATE eical_warnings)
endfunction()
