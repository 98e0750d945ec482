# `dovetail pipeline`: the whole collision pipeline on a scene from files.
set(pl_data ${data}/pipeline)
set(pl_pairs "frame 0 count 1\n0 1\nframe 1 count 2\n0 2\n1 2\nframe 2 count 3\n0 1\n0 2\n1 2\n")
set(pl_keys "\"parts\":3&&\"frames\":3&&\"build_ms\":&&\"ms_per_frame_median\":&&\"pairs_total\":6")

dovetail_cli_test(pipeline_help_contract EXIT 0 ARGS pipeline --help
                  STDOUT "^usage: dovetail pipeline&&--scene FILE&&tx ty tz qw qx qy qz")
dovetail_cli_test(pipeline_listed EXIT 0 ARGS --help STDOUT "pipeline")
dovetail_cli_test(pipeline_stdout EXIT 0 ARGS pipeline --scene ${pl_data}/three_parts.txt
                  STDOUT "^${pl_pairs}{[^\n]*}\n$&&${pl_keys}&&\"broadphase\":\"sap\"&&\"method\":\"obb\"")
# The same pairs with every broad phase and polygon-level method, at 1, 2 and 8 threads.
foreach(combo "sap;obb;1" "grid;boxtree;2" "octree;dop18;8" "brute;aabb;1" "sap;brute;2" "grid;dop6;1" "mbp;obb;8")
  list(GET combo 0 bp)
  list(GET combo 1 method)
  list(GET combo 2 threads)
  dovetail_cli_test(pipeline_${bp}_${method}_${threads} EXIT 0
                    ARGS pipeline --scene ${pl_data}/three_parts.txt --broadphase ${bp}
                         --method ${method} --threads ${threads}
                         --out ${out}/pl_${bp}_${method}.txt
                    STDOUT "^{[^\n]*}\n$&&${pl_keys}"
                    FILE ${out}/pl_${bp}_${method}.txt CONTENT "${pl_pairs}"
                    REMOVE ${out}/pl_${bp}_${method}.txt)
endforeach()

# ---- bad input: an error naming file and line, exit 1, the frames before it written
dovetail_cli_test(pipeline_no_parts EXIT 1 ARGS pipeline --scene ${pl_data}/no_parts.txt
                  STDERR "no_parts.txt:1: no parts [^\n]*but F > 0 frames")
dovetail_cli_test(pipeline_zero_quaternion EXIT 1
                  ARGS pipeline --scene ${pl_data}/zero_quaternion.txt
                  STDERR "zero_quaternion.txt:5: the quaternion is zero")
# A tiny or huge quaternion is a rotation like any other; a far translation is refused.
file(WRITE ${out}/pipeline_quaternions/scene.txt
     "2 1\n${data}/cube.obj\n${data}/cube.obj\n0 0 0 1e-13 0 0 0\n1 0 0 1e300 0 0 1e300\n")
dovetail_cli_test(pipeline_tiny_and_huge_quaternions EXIT 0
                  ARGS pipeline --scene ${out}/pipeline_quaternions/scene.txt STDOUT "\"pairs_total\":1")
file(WRITE ${out}/pipeline_quaternions/far.txt
     "2 1\n${data}/cube.obj\n${data}/cube.obj\n0 0 0 1 0 0 0\n1e300 0 0 1 0 0 0\n")
# A byte-order mark before the first line is skipped.
file(WRITE ${out}/pipeline_quaternions/bom.txt
     "﻿2 1\n${data}/cube.obj\n${data}/cube.obj\n0 0 0 1 0 0 0\n0.5 0 0 1 0 0 0\n")
dovetail_cli_test(pipeline_byte_order_mark EXIT 0 ARGS pipeline --scene ${out}/pipeline_quaternions/bom.txt
                  STDOUT "\"pairs_total\":1")
dovetail_cli_test(pipeline_translation_too_far EXIT 1 ARGS pipeline --scene ${out}/pipeline_quaternions/far.txt
                  STDERR "far.txt:5: a translation beyond the coordinate limit of 1e30")
dovetail_cli_test(pipeline_missing_mesh EXIT 1 ARGS pipeline --scene ${pl_data}/missing_mesh.txt
                  STDERR "missing_mesh.txt:3: mesh of part 1: [^\n]*missing.obj: file not found")
dovetail_cli_test(pipeline_short_pose EXIT 1 ARGS pipeline --scene ${pl_data}/short_pose.txt
                  STDERR "short_pose.txt:6: expected 7 numbers[^\n]*got 6 fields"
                  STDOUT "^frame 0 count 1\n0 1\n{&&\"frames\":1")
dovetail_cli_test(pipeline_extra_data EXIT 1 ARGS pipeline --scene ${pl_data}/extra_data.txt
                  STDERR "extra_data.txt:4: more data than the first line declares")
dovetail_cli_test(pipeline_no_scene EXIT 2 ARGS pipeline STDERR "--scene")
dovetail_cli_test(pipeline_unknown_method EXIT 2
                  ARGS pipeline --scene ${pl_data}/three_parts.txt --method fcl
                  STDERR "unknown --method 'fcl'; valid: boxtree, dop6")
dovetail_cli_test(pipeline_missing_scene EXIT 1 ARGS pipeline --scene ${pl_data}/nothing.txt
                  STDERR "nothing.txt: file not found")

# ---- pair for pair with brute force, at 1, 2 and 8 threads, on generated scenes
if(DOVETAIL_BUILD_BENCH)
  set(engine_glb
      /usr/share/assimp/models/glTF2/2CylinderEngine-glTF-Binary/2CylinderEngine.glb)
  foreach(scene "polytopes;100" "engine;20")
    list(GET scene 0 kind)
    list(GET scene 1 frames)
    if(kind STREQUAL "engine" AND NOT EXISTS ${engine_glb})
      message(STATUS "Dovetail: ${engine_glb} (assimp-testmodels) missing, "
                     "cli.pipeline_agrees_with_brute_force_engine not added")
      continue()
    endif()
    add_test(NAME cli.pipeline_agrees_with_brute_force_${kind}
             COMMAND ${CMAKE_COMMAND} -DPROGRAM=$<TARGET_FILE:dovetail>
                     -DBENCH=$<TARGET_FILE:pipeline_bench> -DKIND=${kind} -DFRAMES=${frames}
                     -DOUT=${out}/pipeline_${kind}
                     -P ${CMAKE_CURRENT_SOURCE_DIR}/pipeline_agreement.cmake)
    set_tests_properties(cli.pipeline_agrees_with_brute_force_${kind} PROPERTIES TIMEOUT 900)
  endforeach()
endif()

# The pairs may not overwrite a mesh the scene lists, and a scene that fails
# before its first frame leaves an existing output as it was.
dovetail_cli_test(pipeline_out_is_mesh EXIT 2
                  ARGS pipeline --scene ${pl_data}/three_parts.txt --out ${data}/cube.obj
                  STDERR "would be overwritten")
dovetail_cli_test(pipeline_bad_scene_keeps_out EXIT 1
                  ARGS pipeline --scene ${pl_data}/missing_mesh.txt --out ${out}/kept_pairs.txt
                  KEEP ${out}/kept_pairs.txt)
