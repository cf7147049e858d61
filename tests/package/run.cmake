# Installs the build tree BUILD_DIR into WORK_DIR/prefix, then configures, builds and runs the
# consumer project SOURCE_DIR against it. Fails on any step.
file(REMOVE_RECURSE ${WORK_DIR})
function(step)
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "failed: ${ARGN}\n${out}\n${err}")
  endif()
  message("${out}")
endfunction()
step(${CMAKE_COMMAND} --install ${BUILD_DIR} --prefix ${WORK_DIR}/prefix)
foreach(f include/halfback/core/param.hpp bin/halfback share/man/man1/halfback.1)
  if(NOT EXISTS ${WORK_DIR}/prefix/${f})
    message(FATAL_ERROR "not installed: ${f}")
  endif()
endforeach()
step(${CMAKE_COMMAND} -S ${SOURCE_DIR} -B ${WORK_DIR}/build -G ${GENERATOR}
     -DCMAKE_PREFIX_PATH=${WORK_DIR}/prefix -DCMAKE_BUILD_TYPE=Release)
step(${CMAKE_COMMAND} --build ${WORK_DIR}/build)
step(${WORK_DIR}/build/consumer)
step(${WORK_DIR}/prefix/bin/halfback --version)
# A consumer of the core alone: found without Cairo, OpenEXR or Eigen (core/CMakeLists.txt forbids
# finding them), and compiled without their include paths.
step(${CMAKE_COMMAND} -S ${SOURCE_DIR}/core -B ${WORK_DIR}/core-build -G ${GENERATOR}
     -DCMAKE_PREFIX_PATH=${WORK_DIR}/prefix -DCMAKE_BUILD_TYPE=Release)
step(${CMAKE_COMMAND} --build ${WORK_DIR}/core-build)
step(${WORK_DIR}/core-build/core_consumer)
file(READ ${WORK_DIR}/core-build/compile_commands.json commands)
foreach(forbidden cairo OpenEXR Imath eigen3 glib)
  string(FIND "${commands}" "${forbidden}" at)
  if(NOT at EQUAL -1)
    message(FATAL_ERROR "the core consumer is compiled with a ${forbidden} path:\n${commands}")
  endif()
endforeach()
# A consumer of the acquisition layer alone (a laboratory's planning tool): found without Ceres or
# Eigen and compiled without Cairo's, Ceres's or Eigen's include paths. OpenEXR and HDF5 stay on its
# link line: they come through formats, whose MERL/RGL writers a reconstruction uses, and formats
# is one library (docs/architecture.md).
step(${CMAKE_COMMAND} -S ${SOURCE_DIR}/acquire -B ${WORK_DIR}/acquire-build -G ${GENERATOR}
     -DCMAKE_PREFIX_PATH=${WORK_DIR}/prefix -DCMAKE_BUILD_TYPE=Release)
step(${CMAKE_COMMAND} --build ${WORK_DIR}/acquire-build)
step(${WORK_DIR}/acquire-build/acquire_consumer)
file(READ ${WORK_DIR}/acquire-build/compile_commands.json commands)
foreach(forbidden cairo ceres eigen3)
  string(FIND "${commands}" "${forbidden}" at)
  if(NOT at EQUAL -1)
    message(FATAL_ERROR "the acquire consumer is compiled with a ${forbidden} path:\n${commands}")
  endif()
endforeach()
# The installed Python package, when the module was built.
set(pydir ${WORK_DIR}/prefix/lib/python3/dist-packages)
if(PYTHON AND EXISTS ${pydir}/halfback/__init__.py)
  step(${CMAKE_COMMAND} -E env PYTHONPATH=${pydir} ${PYTHON} -c
       "print(__import__('halfback').load('lambert').eval([[0, 0, 1]], [[0, 0, 1]]))")
  # (no ';' in the code: step() passes its arguments as a CMake list)
endif()
