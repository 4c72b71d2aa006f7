# The rooms' rule, run by CTest as `layers`: every include points down the
# stack raster -> scene -> shading -> renderer -> stepper -> apps and tools.
# Fails naming each line that crosses the wrong way.
#   cmake -DSOURCE_DIR=... -P tests/check_layers.cmake
set(_bad "")
foreach(_rule "raster:scene|shading|renderer|stepper|apps|tools"
              "scene:shading|renderer|stepper|apps|tools"
              "shading:renderer|stepper|apps|tools"
              "renderer:stepper|apps|tools"
              "stepper:apps|tools")
  string(REPLACE ":" ";" _parts "${_rule}")
  list(GET _parts 0 _folder)
  list(GET _parts 1 _forbidden)
  file(GLOB_RECURSE _files ${SOURCE_DIR}/${_folder}/*.h ${SOURCE_DIR}/${_folder}/*.cpp)
  foreach(_f ${_files})
    file(STRINGS ${_f} _lines REGEX "^[ \t]*#[ \t]*include[ \t]*[\"<](prast/)?(${_forbidden})/")
    foreach(_l ${_lines})
      file(RELATIVE_PATH _rel ${SOURCE_DIR} ${_f})
      string(STRIP "${_l}" _l)
      list(APPEND _bad "${_rel}: ${_l}")
    endforeach()
  endforeach()
endforeach()
if(_bad)
  list(JOIN _bad "\n  " _msg)
  message(FATAL_ERROR "includes that cross the layers the wrong way:\n  ${_msg}")
endif()
message(STATUS "layers: raster -> scene -> shading -> renderer -> stepper -> apps, tools: ok")
