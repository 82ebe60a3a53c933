# Fuzz targets (label "fuzz"), built only with -DGAITSIM_FUZZ=ON and clang:
#   CC=clang cmake -S . -B build-fuzz -DGAITSIM_FUZZ=ON
#   cmake --build build-fuzz --target fuzz_storage fuzz_solution fuzz_options
#   ctest --test-dir build-fuzz -L fuzz          (30 s each; scripts/fuzz.sh SECONDS for longer)
# fuzz_storage: the storage/CSV reader; its io sources are compiled straight into the fuzzer so
# that all of it is instrumented. fuzz_solution (the solution-folder check of every reader) and
# fuzz_options (the option readers, Ipopt option files) link gaitsim_core, which this
# configuration instruments for coverage and the sanitizers.
if(GAITSIM_FUZZ)
  if(NOT CMAKE_C_COMPILER_ID MATCHES "Clang")
    message(FATAL_ERROR "GAITSIM_FUZZ needs clang (libFuzzer): configure with CC=clang")
  endif()
  set(GS_FUZZ_FLAGS -fsanitize=fuzzer,address,undefined -fno-sanitize-recover=undefined
                    -fno-omit-frame-pointer -g)

  add_executable(fuzz_storage
    ${CMAKE_CURRENT_SOURCE_DIR}/fuzz/fuzz_storage.c
    ${PROJECT_SOURCE_DIR}/io/gs_storage.c
    ${PROJECT_SOURCE_DIR}/io/gs_table.c
    ${PROJECT_SOURCE_DIR}/io/gs_atomic.c
    ${PROJECT_SOURCE_DIR}/io/gs_text.c)
  target_include_directories(fuzz_storage PRIVATE ${PROJECT_SOURCE_DIR})
  target_compile_options(fuzz_storage PRIVATE ${GS_FUZZ_FLAGS})
  target_link_options(fuzz_storage PRIVATE ${GS_FUZZ_FLAGS})
  target_link_libraries(fuzz_storage PRIVATE m)

  # new inputs go to the build tree; the seed corpus in the source tree stays read-only
  set(GS_FUZZ_WORK ${CMAKE_CURRENT_BINARY_DIR}/fuzz_storage_work)
  file(MAKE_DIRECTORY ${GS_FUZZ_WORK}/corpus ${GS_FUZZ_WORK}/artifacts)
  add_test(NAME fuzz_storage
    COMMAND fuzz_storage -max_total_time=30 -rss_limit_mb=1024 -timeout=10 -max_len=8192
            -print_final_stats=1 -dict=${CMAKE_CURRENT_SOURCE_DIR}/fuzz/storage.dict
            -artifact_prefix=${GS_FUZZ_WORK}/artifacts/
            ${GS_FUZZ_WORK}/corpus ${CMAKE_CURRENT_SOURCE_DIR}/fuzz/corpus_storage)
  set_tests_properties(fuzz_storage PROPERTIES LABELS fuzz TIMEOUT 120)

  # readers inside the library: gaitsim_core instrumented (coverage for libFuzzer, ASan, UBSan)
  target_compile_options(gaitsim_core PRIVATE -fsanitize=fuzzer-no-link,address,undefined
                                              -fno-sanitize-recover=undefined -fno-omit-frame-pointer)
  target_link_options(gaitsim_core INTERFACE -fsanitize=address,undefined)
  foreach(target fuzz_solution fuzz_options)
    add_executable(${target} ${CMAKE_CURRENT_SOURCE_DIR}/fuzz/${target}.c)
    target_link_libraries(${target} PRIVATE gaitsim_core)
    target_compile_options(${target} PRIVATE ${GS_FUZZ_FLAGS})
    target_link_options(${target} PRIVATE ${GS_FUZZ_FLAGS})
    set(work ${CMAKE_CURRENT_BINARY_DIR}/${target}_work)
    file(MAKE_DIRECTORY ${work}/corpus ${work}/artifacts)
    add_test(NAME ${target}
      COMMAND ${target} -max_total_time=30 -rss_limit_mb=2048 -timeout=10 -max_len=8192
              -close_fd_mask=2 -print_final_stats=1 -artifact_prefix=${work}/artifacts/
              ${work}/corpus ${CMAKE_CURRENT_SOURCE_DIR}/fuzz/corpus_${target})
    set_tests_properties(${target} PROPERTIES LABELS fuzz TIMEOUT 120)
  endforeach()
endif()
