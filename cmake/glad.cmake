# A GL 3.3 core loader generated at build time by Debian's python3-glad (offline, --reproducible).
# The loader takes a get-proc-address function, so the same renderer runs in an SDL window and in
# an off-screen OSMesa context (see ../shared/docs/references.md).
find_program(DRAPE_SYSTEM_PYTHON python3 PATHS /usr/bin NO_DEFAULT_PATH REQUIRED)
set(DRAPE_GLAD_DIR "${CMAKE_BINARY_DIR}/glad")
add_custom_command(
  OUTPUT "${DRAPE_GLAD_DIR}/src/gl.c" "${DRAPE_GLAD_DIR}/include/glad/gl.h"
  COMMAND "${DRAPE_SYSTEM_PYTHON}" -m glad --api gl:core=3.3 --out-path "${DRAPE_GLAD_DIR}" --reproducible --quiet c
  COMMENT "Generating the GL 3.3 core loader with glad"
  VERBATIM)
add_library(drape_glad STATIC "${DRAPE_GLAD_DIR}/src/gl.c")
target_include_directories(drape_glad PUBLIC "${DRAPE_GLAD_DIR}/include")
set_target_properties(drape_glad PROPERTIES POSITION_INDEPENDENT_CODE ON)
