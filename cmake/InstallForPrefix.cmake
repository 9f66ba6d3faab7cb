# Install-time half of cmake/Packaging.cmake, included by cmake_install.cmake.
#
# A few installed files depend on the prefix: the systemd units name
# <prefix>/bin/resolverd, and Debian's Python looks for packages in
# /usr/lib/python3/dist-packages but /usr/local/lib/python3.X/dist-packages.
# The prefix is only known when installing (cmake --install --prefix P, or
# CPack's /usr for the .deb, which runs with CPACK_SET_DESTDIR so the prefix
# here is the final one and DESTDIR the staging root), so these are resolved
# here, from CMAKE_INSTALL_PREFIX, instead of at configure time.

# resolver_install_configured(TEMPLATE OUT_NAME DESTINATION BINDIR DOCDIR WORK_DIR)
# Configures TEMPLATE's @CMAKE_INSTALL_FULL_BINDIR@ and @CMAKE_INSTALL_FULL_DOCDIR@
# for the install prefix into WORK_DIR/OUT_NAME and installs that file to DESTINATION
# (relative to the prefix, or absolute). BINDIR/DOCDIR: GNUInstallDirs' (relative or absolute).
function(resolver_install_configured template out_name destination bindir docdir work_dir)
  foreach(kind BINDIR DOCDIR)
    string(TOLOWER ${kind} arg)
    if(IS_ABSOLUTE "${${arg}}")
      set(CMAKE_INSTALL_FULL_${kind} "${${arg}}")
    else()
      set(CMAKE_INSTALL_FULL_${kind} "${CMAKE_INSTALL_PREFIX}/${${arg}}")
    endif()
  endforeach()
  configure_file("${template}" "${work_dir}/${out_name}" @ONLY)
  if(NOT IS_ABSOLUTE "${destination}")
    set(destination "${CMAKE_INSTALL_PREFIX}/${destination}")
  endif()
  file(INSTALL DESTINATION "${destination}" TYPE FILE FILES "${work_dir}/${out_name}")
endfunction()

# resolver_install_python_package(PACKAGE_DIR CONFIGURED_DIR PYTHON_MINOR)
# Installs the package folder where Debian's python3 finds it for this prefix,
# or in CONFIGURED_DIR when RESOLVER_PYTHON_INSTALL_DIR was set at configure time.
function(resolver_install_python_package package_dir configured_dir python_minor)
  if(NOT "${configured_dir}" STREQUAL "")
    set(dir "${configured_dir}")
  elseif(CMAKE_INSTALL_PREFIX STREQUAL "/usr")
    set(dir "lib/python3/dist-packages")  # Debian's own packages: every python3 version
  else()
    set(dir "lib/python3.${python_minor}/dist-packages")  # on sys.path for /usr/local
  endif()
  if(NOT IS_ABSOLUTE "${dir}")
    set(dir "${CMAKE_INSTALL_PREFIX}/${dir}")
  endif()
  file(INSTALL DESTINATION "${dir}" TYPE DIRECTORY FILES "${package_dir}"
       PATTERN "__pycache__" EXCLUDE PATTERN "*.pyc" EXCLUDE)
endfunction()
