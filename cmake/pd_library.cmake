# pd_library.cmake -- the Pd library folder `ictus/` as users get it, from
# `cmake --install` (component pd_library, into <prefix>/lib/pd-externals/ictus)
# and from the deken package (`cmake --build <build> --target deken`, which
# installs that same component into <build>/deken/ and zips it with ictusd,
# cmake/deken.cmake). Included by the top CMakeLists.txt after the externals
# and patches have registered their files (global properties
# ICTUS_PD_LIBRARY_TARGETS and ICTUS_PD_LIBRARY_FILES): one list for both.
set(ictus_pd_dest lib/pd-externals/ictus)

get_property(ictus_pd_targets GLOBAL PROPERTY ICTUS_PD_LIBRARY_TARGETS)
get_property(ictus_pd_files GLOBAL PROPERTY ICTUS_PD_LIBRARY_FILES)
# install(TARGETS) sets each binary's RUNPATH to its INSTALL_RPATH ($ORIGIN for
# the loaders, none otherwise): never the build folder.
install(TARGETS ${ictus_pd_targets}
        LIBRARY DESTINATION ${ictus_pd_dest} COMPONENT pd_library
        RUNTIME DESTINATION ${ictus_pd_dest} COMPONENT pd_library
        ARCHIVE DESTINATION ${ictus_pd_dest} COMPONENT pd_library)
# Abstractions, help patches, the meta file.
install(FILES ${ictus_pd_files} DESTINATION ${ictus_pd_dest} COMPONENT pd_library)
# The sound-clip model's clips, rendered at build time (patches/sound).
if(TARGET ictus_sound_clips)
  install(FILES ${ICTUS_PD_LIBDIR}/clips/ictus-clips.wav DESTINATION ${ictus_pd_dest}/clips
          COMPONENT pd_library)
endif()
# The main patch and the offline render of any sound model, beside the
# abstractions: the main patch's [declare -path ../ictus] names its own folder
# there. (ictus-render.pd, an events file on the drum, is among the library
# files already: externals/pd/CMakeLists.txt, for ictusd render --wav.)
install(FILES ${ICTUS_SOURCE_ROOT}/patches/ictus.pd
              ${ICTUS_SOURCE_ROOT}/patches/sound/ictus-sound-render.pd
        DESTINATION ${ictus_pd_dest} COMPONENT pd_library)
install(FILES ${ICTUS_SOURCE_ROOT}/examples/scores/figure5.txt
              ${ICTUS_SOURCE_ROOT}/examples/scores/groove.txt
              ${ICTUS_SOURCE_ROOT}/examples/scores/kit.txt
              ${ICTUS_SOURCE_ROOT}/examples/scores/nuances.txt
              ${ICTUS_SOURCE_ROOT}/examples/scores/rudiments.txt
              ${ICTUS_SOURCE_ROOT}/examples/scores/tempo_ramp.txt
        DESTINATION ${ictus_pd_dest}/examples/scores COMPONENT pd_library)
install(FILES ${ICTUS_SOURCE_ROOT}/README.md ${ICTUS_SOURCE_ROOT}/LICENSE
        DESTINATION ${ictus_pd_dest} COMPONENT pd_library)

# The references (docs/*.md, their figures, and the same pages as HTML made by
# scripts/doc_html.py with Debian's python3-markdown) in docs/ beside the help
# patches: the patches' "docs/NAME.md" resolve there.
file(GLOB ictus_doc_sources ${ICTUS_SOURCE_ROOT}/docs/*.md)
file(GLOB ictus_doc_images ${ICTUS_SOURCE_ROOT}/docs/img/*.png)
install(FILES ${ictus_doc_sources} DESTINATION ${ictus_pd_dest}/docs COMPONENT pd_library)
install(FILES ${ictus_doc_images} DESTINATION ${ictus_pd_dest}/docs/img COMPONENT pd_library)
find_program(ICTUS_DOC_PYTHON NAMES python3 PATHS /usr/bin NO_DEFAULT_PATH)
set(ictus_doc_markdown OFF)
if(ICTUS_DOC_PYTHON)
  execute_process(COMMAND ${ICTUS_DOC_PYTHON} -c "import markdown" RESULT_VARIABLE rc
                  OUTPUT_QUIET ERROR_QUIET)
  if(rc EQUAL 0)
    set(ictus_doc_markdown ON)
  endif()
endif()
if(ictus_doc_markdown)
  set(ictus_doc_html_dir ${CMAKE_BINARY_DIR}/docs-html)
  set(ictus_doc_html "")
  foreach(src ${ictus_doc_sources})
    get_filename_component(name ${src} NAME_WE)
    list(APPEND ictus_doc_html ${ictus_doc_html_dir}/${name}.html)
  endforeach()
  add_custom_command(OUTPUT ${ictus_doc_html}
    COMMAND ${ICTUS_DOC_PYTHON} ${ICTUS_SOURCE_ROOT}/scripts/doc_html.py ${ictus_doc_html_dir}
            ${ictus_doc_sources}
    DEPENDS ${ictus_doc_sources} ${ICTUS_SOURCE_ROOT}/scripts/doc_html.py
    COMMENT "The references as HTML for the Pd library"
    VERBATIM)
  add_custom_target(ictus_docs_html ALL DEPENDS ${ictus_doc_html})
  install(FILES ${ictus_doc_html} DESTINATION ${ictus_pd_dest}/docs COMPONENT pd_library)
else()
  message(WARNING "python3-markdown not found (bash scripts/deps.sh installs it): the Pd "
                  "library ships the references as Markdown only")
endif()

# The deken package: LIBRARY[vVERSION](OS-MARCH-FLOATSIZE).dek, a zip of the
# folder ictus/ (deken's naming; Pd's float is 32-bit in Debian's pd).
if(CMAKE_SYSTEM_NAME STREQUAL "Linux")
  set(ictus_deken_os Linux)
elseif(APPLE)
  set(ictus_deken_os Darwin)
elseif(WIN32)
  set(ictus_deken_os Windows)
else()
  set(ictus_deken_os ${CMAKE_SYSTEM_NAME})
endif()
string(TOLOWER "${CMAKE_SYSTEM_PROCESSOR}" ictus_deken_cpu)
if(ictus_deken_cpu MATCHES "^(x86_64|amd64)$")
  set(ictus_deken_cpu amd64)
elseif(ictus_deken_cpu MATCHES "^(aarch64|arm64)$")
  set(ictus_deken_cpu arm64)
elseif(ictus_deken_cpu MATCHES "^i.86$")
  set(ictus_deken_cpu i386)
endif()
set(ICTUS_DEKEN_FILE
    "${CMAKE_BINARY_DIR}/ictus[v${PROJECT_VERSION}](${ictus_deken_os}-${ictus_deken_cpu}-32).dek")
set(ictus_deken_ictusd "")
set(ictus_deken_depends ${ictus_pd_targets})
if(TARGET ictusd)
  set(ictus_deken_ictusd $<TARGET_FILE:ictusd>)
  list(APPEND ictus_deken_depends ictusd)
endif()
if(TARGET ictus_sound_clips)
  list(APPEND ictus_deken_depends ictus_sound_clips)
endif()
if(TARGET ictus_docs_html)
  list(APPEND ictus_deken_depends ictus_docs_html)
endif()
add_custom_target(deken
  COMMAND ${CMAKE_COMMAND} -DBUILD_DIR=${CMAKE_BINARY_DIR} -DSTAGE_DIR=${CMAKE_BINARY_DIR}/deken
          -DDEK_FILE=${ICTUS_DEKEN_FILE} -DICTUSD=${ictus_deken_ictusd}
          -P ${ICTUS_SOURCE_ROOT}/cmake/deken.cmake
  COMMENT "Packing the Pd library ictus/ and ictusd as a deken package"
  VERBATIM)
add_dependencies(deken ${ictus_deken_depends})
