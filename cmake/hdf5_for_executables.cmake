# The target fiberlab_hdf5: HDF5's headers for every target, and for linking
# - executables (fiberlab, tests, benchmarks): Debian's static archive
#   (libhdf5-dev ships it) with the archives of its compression filters, when
#   they are installed and a test program links with them;
# - shared objects (the Python module), or when the archive is missing or
#   FIBERLAB_STATIC_HDF5 is OFF: the shared library (HDF5::HDF5).
# Why: Debian's shared libhdf5 needs about 27 more shared libraries (libcurl
# and its TLS and Kerberos chain, for a remote-file driver fiberlab never
# uses). Loading them costs about 11 ms of every run's start-up. The archive
# only brings what fiberlab calls.
option(FIBERLAB_STATIC_HDF5 "Link executables with HDF5's static archive when it is installed" ON)

add_library(fiberlab_hdf5 INTERFACE)
target_include_directories(fiberlab_hdf5 INTERFACE
  $<TARGET_PROPERTY:HDF5::HDF5,INTERFACE_INCLUDE_DIRECTORIES>)
target_compile_definitions(fiberlab_hdf5 INTERFACE
  $<TARGET_PROPERTY:HDF5::HDF5,INTERFACE_COMPILE_DEFINITIONS>)

set(FIBERLAB_HDF5_LINKED "shared")
if(FIBERLAB_STATIC_HDF5)
  get_filename_component(_hdf5_dir "${HDF5_C_LIBRARY_hdf5}" DIRECTORY)
  find_library(FIBERLAB_HDF5_ARCHIVE NAMES libhdf5.a PATHS "${_hdf5_dir}" NO_DEFAULT_PATH)
  find_library(FIBERLAB_SZ_ARCHIVE NAMES libsz.a)
  find_library(FIBERLAB_AEC_ARCHIVE NAMES libaec.a)
  find_library(FIBERLAB_Z_ARCHIVE NAMES libz.a)
  set(_hdf5_static ${FIBERLAB_HDF5_ARCHIVE} ${FIBERLAB_SZ_ARCHIVE} ${FIBERLAB_AEC_ARCHIVE}
      ${FIBERLAB_Z_ARCHIVE} ${CMAKE_DL_LIBS} m)
  if(FIBERLAB_HDF5_ARCHIVE AND FIBERLAB_SZ_ARCHIVE AND FIBERLAB_AEC_ARCHIVE AND FIBERLAB_Z_ARCHIVE)
    include(CheckCSourceCompiles)
    set(CMAKE_REQUIRED_INCLUDES ${HDF5_C_INCLUDE_DIRS})
    find_package(Threads REQUIRED)
    set(CMAKE_REQUIRED_LIBRARIES ${_hdf5_static} Threads::Threads)
    check_c_source_compiles([[
      #include <hdf5.h>
      int main(void) {
        hid_t p = H5Pcreate(H5P_DATASET_CREATE);
        return H5open() < 0 || H5Pset_deflate(p, 2) < 0 || H5Fcreate("x", H5F_ACC_EXCL, H5P_DEFAULT, H5P_DEFAULT) < 0;
      }
    ]] FIBERLAB_HDF5_ARCHIVE_LINKS)
    unset(CMAKE_REQUIRED_INCLUDES)
    unset(CMAKE_REQUIRED_LIBRARIES)
    if(FIBERLAB_HDF5_ARCHIVE_LINKS)
      set(FIBERLAB_HDF5_LINKED "static for executables")
    endif()
  endif()
endif()

if(FIBERLAB_HDF5_LINKED STREQUAL "shared")
  target_link_libraries(fiberlab_hdf5 INTERFACE HDF5::HDF5)
else()
  # $<TARGET_PROPERTY:TYPE> is the type of the target being linked.
  target_link_libraries(fiberlab_hdf5 INTERFACE
    "$<IF:$<STREQUAL:$<TARGET_PROPERTY:TYPE>,EXECUTABLE>,${_hdf5_static};Threads::Threads,HDF5::HDF5>")
endif()
message(STATUS "fiberlab: HDF5 ${FIBERLAB_HDF5_LINKED}")
