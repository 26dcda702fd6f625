# Writes the module ropedyn_version (OUT, from the template IN) with the code version: the
# project's version (PROJECT_VERSION) and, when SOURCE_DIR is a git checkout and GIT is
# given, "+g" and `git describe --always --tags` of it. When what the build is made of
# (src solvers CMakeLists.txt cmake) has uncommitted changes, "-dirty", a dot and the first
# 8 hex digits of the SHA-256 of those changes (`git diff HEAD` on them, and the files not
# in git yet with their contents): two builds of one commit with the same edits say the
# same, other edits say otherwise, and edits elsewhere (docs, tools, tests) leave the
# commit's version (a study keeps the case files of its own code by this text).
#
# Run with `cmake -P` at every build (the target ropedyn_version_file), not once at
# configure time: a commit or an edit after configuring must show in the version that every
# output file records. configure_file leaves OUT untouched when its text is the same, so an
# unchanged version compiles nothing again.
set(ROPEDYN_VERSION "${PROJECT_VERSION}")
if(GIT)
    execute_process(COMMAND ${GIT} describe --always --tags
                    WORKING_DIRECTORY ${SOURCE_DIR}
                    OUTPUT_VARIABLE described OUTPUT_STRIP_TRAILING_WHITESPACE
                    ERROR_QUIET RESULT_VARIABLE git_rc)
    if(git_rc EQUAL 0 AND described)
        set(ROPEDYN_VERSION "${PROJECT_VERSION}+g${described}")
        set(parts src solvers CMakeLists.txt cmake)
        execute_process(COMMAND ${GIT} diff HEAD -- ${parts}
                        WORKING_DIRECTORY ${SOURCE_DIR}
                        OUTPUT_VARIABLE changes ERROR_QUIET)
        # files not in git yet (a new source the build globs) count with their contents
        execute_process(COMMAND ${GIT} ls-files --others --exclude-standard -- ${parts}
                        WORKING_DIRECTORY ${SOURCE_DIR}
                        OUTPUT_VARIABLE untracked OUTPUT_STRIP_TRAILING_WHITESPACE ERROR_QUIET)
        if(untracked)
            string(REPLACE "\n" ";" untracked "${untracked}")
            foreach(name IN LISTS untracked)
                file(SHA256 ${SOURCE_DIR}/${name} sum)
                string(APPEND changes "new ${name} ${sum}\n")
            endforeach()
        endif()
        if(changes)
            string(SHA256 digest "${changes}")
            string(SUBSTRING "${digest}" 0 8 digest)
            string(APPEND ROPEDYN_VERSION "-dirty.${digest}")
        endif()
    endif()
endif()
configure_file(${IN} ${OUT} @ONLY)
