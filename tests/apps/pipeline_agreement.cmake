# `dovetail pipeline` against brute force on a generated scene:
#   cmake -DPROGRAM=dovetail -DBENCH=pipeline_bench -DKIND=engine|polytopes -DFRAMES=F
#         -DOUT=dir -P pipeline_agreement.cmake
# writes the scene with `pipeline_bench scene`, runs the pipeline with the
# brute-force broad phase and triangle test, then with every broad phase and
# the OBB, DOP and Boxtree levels at 1, 2 and 8 threads, and fails unless
# every run writes the same pairs, frame for frame.

function(run_pipeline name)
  execute_process(COMMAND ${PROGRAM} pipeline --scene ${OUT}/scene.txt ${ARGN}
                          --out ${OUT}/${name}.txt
                  RESULT_VARIABLE code OUTPUT_VARIABLE json ERROR_VARIABLE err)
  if(NOT code EQUAL 0)
    message(FATAL_ERROR "pipeline ${ARGN}: exit ${code}\n${err}")
  endif()
  string(STRIP "${json}" json)
  message(STATUS "${json}")
endfunction()

file(REMOVE_RECURSE ${OUT})
execute_process(COMMAND ${BENCH} scene ${KIND} ${OUT} --frames ${FRAMES}
                RESULT_VARIABLE code ERROR_VARIABLE err)
if(NOT code EQUAL 0)
  message(FATAL_ERROR "pipeline_bench scene ${KIND}: exit ${code}\n${err}")
endif()

run_pipeline(brute --broadphase brute --method brute)
file(READ ${OUT}/brute.txt reference)
string(REGEX MATCHALL "\n[0-9]+ [0-9]+" pairs "${reference}")
list(LENGTH pairs count)
if(count EQUAL 0)
  message(FATAL_ERROR "brute force finds no intersecting pair: the scene tests nothing")
endif()
message(STATUS "brute force: ${count} intersecting pairs over ${FRAMES} frames")

foreach(combo "sap;obb;1" "sap;obb;2" "sap;obb;8" "grid;obb;2" "octree;obb;8" "sap;dop18;2"
              "grid;boxtree;1" "octree;aabb;2" "mbp;obb;2")
  list(GET combo 0 broadphase)
  list(GET combo 1 method)
  list(GET combo 2 threads)
  set(name ${broadphase}_${method}_${threads})
  run_pipeline(${name} --broadphase ${broadphase} --method ${method} --threads ${threads})
  file(READ ${OUT}/${name}.txt pairs_found)
  if(NOT pairs_found STREQUAL reference)
    message(FATAL_ERROR "${name}: the pairs differ from brute force (${OUT}/${name}.txt, "
                        "${OUT}/brute.txt)")
  endif()
endforeach()
