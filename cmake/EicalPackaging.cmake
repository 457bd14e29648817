# Installation and the Debian package (CPack):
#   cmake --build BUILD --target package   →   BUILD/eical_<version>_<arch>.deb
# with eicald and eical in /usr/bin, the systemd unit, /etc/eical/eicald.toml and
# /etc/eical/cyclonedds.xml as conffiles, /etc/eical/programs (the program set-point's
# programs), the LinuxCNC kit, the documentation (README, docs/) and the man pages;
# postinst creates the system user eical and /var/lib/eical/runs (packaging/debian).
if(EICAL_BUILD_DAEMON)
  install(TARGETS eicald RUNTIME DESTINATION bin)
  install(FILES ${PROJECT_SOURCE_DIR}/systemd/eicald.service DESTINATION /lib/systemd/system)
  install(FILES ${PROJECT_SOURCE_DIR}/config/eicald.toml DESTINATION /etc/eical)
  install(FILES ${PROJECT_SOURCE_DIR}/config/cyclonedds-loopback.xml DESTINATION /etc/eical RENAME cyclonedds.xml)
  install(DIRECTORY DESTINATION /etc/eical/programs)
endif()
if(EICAL_BUILD_TOOLS)
  install(TARGETS eical RUNTIME DESTINATION bin)
endif()
install(FILES ${PROJECT_SOURCE_DIR}/README.md DESTINATION share/doc/eical)
install(DIRECTORY ${PROJECT_SOURCE_DIR}/docs/ DESTINATION share/doc/eical/docs FILES_MATCHING PATTERN "*.md")
# The man pages: eical(1), eicald(8), eicald.toml(5) (docs/man).
install(FILES ${PROJECT_SOURCE_DIR}/docs/man/eical.1 DESTINATION share/man/man1)
install(FILES ${PROJECT_SOURCE_DIR}/docs/man/eicald.8 DESTINATION share/man/man8)
install(FILES ${PROJECT_SOURCE_DIR}/docs/man/eicald.toml.5 DESTINATION share/man/man5)
install(DIRECTORY ${PROJECT_SOURCE_DIR}/config/examples ${PROJECT_SOURCE_DIR}/config/scenarios DESTINATION share/doc/eical)
install(DIRECTORY ${PROJECT_SOURCE_DIR}/integrations/linuxcnc DESTINATION share/eical/integrations USE_SOURCE_PERMISSIONS)

set(CPACK_GENERATOR DEB)
set(CPACK_PACKAGE_NAME eical)
set(CPACK_PACKAGE_VERSION ${PROJECT_VERSION})
set(CPACK_PACKAGING_INSTALL_PREFIX /usr)
set(CPACK_PACKAGE_DESCRIPTION_SUMMARY "embedded inertial calibrator for CNC machine tools (eicald service, eical command line)")
set(CPACK_PACKAGE_CONTACT "eical maintainers <eical@localhost>")
set(CPACK_DEBIAN_FILE_NAME DEB-DEFAULT)  # eical_<version>_<arch>.deb
set(CPACK_DEBIAN_PACKAGE_SECTION science)
set(CPACK_DEBIAN_PACKAGE_SHLIBDEPS ON)    # the runtime libraries the binaries link (dpkg-shlibdeps)
set(CPACK_DEBIAN_PACKAGE_DEPENDS "passwd, systemd")
set(CPACK_DEBIAN_PACKAGE_CONTROL_EXTRA
    ${PROJECT_SOURCE_DIR}/packaging/debian/conffiles ${PROJECT_SOURCE_DIR}/packaging/debian/postinst
    ${PROJECT_SOURCE_DIR}/packaging/debian/prerm ${PROJECT_SOURCE_DIR}/packaging/debian/postrm)
set(CPACK_DEBIAN_PACKAGE_CONTROL_STRICT_PERMISSION ON)
include(CPack)
