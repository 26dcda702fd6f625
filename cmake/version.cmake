# Writes the module ropedyn_version (OUT, from the template IN) with the code version: the
# project's version (PROJECT_VERSION) and, when SOURCE_DIR is a git checkout and GIT is
# given, "+g" and `git describe --always --dirty --tags` of it. A tree with uncommitted
# changes ("-dirty") gets a dot and the first 8 hex digits of the SHA-256 of its
# uncommitted changes to what the build is made of (`git diff HEAD -- src solvers
# CMakeLists.txt cmake`): two builds of one commit with the same edits say the same, and
# other edits say otherwise (a study keeps the case files of its own code by this text).
#
# Run with `cmake -P` at every build (the target ropedyn_version_file), not once at
# configure time: a commit or an edit after configuring must show in the version that every
# output file records. configure_file leaves OUT untouched when its text is the same, so an
# unchanged version compiles nothing again.
set(ROPEDYN_VERSION "${PROJECT_VERSION}")
if(GIT)
    execute_process(COMMAND ${GIT} describe --always --dirty --tags
                    WORKING_DIRECTORY ${SOURCE_DIR}
                    OUTPUT_VARIABLE described OUTPUT_STRIP_TRAILING_WHITESPACE
                    ERROR_QUIET RESULT_VARIABLE git_rc)
    if(git_rc EQUAL 0 AND described)
        set(ROPEDYN_VERSION "${PROJECT_VERSION}+g${described}")
        if(described MATCHES "-dirty$")
            execute_process(COMMAND ${GIT} diff HEAD -- src solvers CMakeLists.txt cmake
                            WORKING_DIRECTORY ${SOURCE_DIR}
                            OUTPUT_VARIABLE changes ERROR_QUIET)
            string(SHA256 digest "${changes}")
            string(SUBSTRING "${digest}" 0 8 digest)
            string(APPEND ROPEDYN_VERSION ".${digest}")
        endif()
    endif()
endif()
configure_file(${IN} ${OUT} @ONLY)
