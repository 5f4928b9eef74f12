# Fails when a file under src/atmos/models/ named reference* (the path tracer,
# the ground truth) includes another model's header (a model under test; issue
# 30 item 3). Allowed from models/: its own files and the host adapters every
# model shares (evaluator_model.h, option_json.h). Run by ctest:
# layering_reference_includes_no_model.
file(GLOB files ${DIR}/reference*.h ${DIR}/reference*.cpp)
if(NOT files)
  message(FATAL_ERROR "no reference sources under ${DIR}")
endif()
set(bad "")
foreach(f ${files})
  file(STRINGS ${f} lines REGEX "^[ \t]*#[ \t]*include[ \t]*[\"<]models/")
  foreach(line ${lines})
    if(NOT line MATCHES "models/(reference[A-Za-z0-9_]*|evaluator_model|option_json)\\.h")
      list(APPEND bad "${f}: ${line}")
    endif()
  endforeach()
endforeach()
if(bad)
  string(REPLACE ";" "\n" bad "${bad}")
  message(FATAL_ERROR "the reference must not include a model under test:\n${bad}")
endif()
message(STATUS "models/reference*: no model under test included")
