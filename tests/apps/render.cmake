# `dovetail render`: included from CMakeLists.txt, uses its dovetail_cli_test.

set(render_engine
    /usr/share/assimp/models/glTF2/2CylinderEngine-glTF-Binary/2CylinderEngine.glb)
set(render_keys "\"width\":160&&\"height\":120&&\"camera\":\"auto\"&&\"parts\":[1-9]&&\"triangles\":[1-9]")

dovetail_cli_test(render_help EXIT 0 ARGS render --help
                  STDOUT "^usage: dovetail render INPUT --out PNG&&--width&&--height&&--camera")
dovetail_cli_test(render_listed EXIT 0 ARGS --help STDOUT "render ")

# ---- results: a PNG of the asked size, the same bytes every time
foreach(run first second)
  dovetail_cli_test(render_engine_${run} EXIT 0
                    ARGS render ${render_engine} --out ${out}/render_${run}.png --width 160
                         --height 120
                    STDOUT "^{[^\n]*}\n$&&${render_keys}" REMOVE ${out}/render_${run}.png)
  set_tests_properties(cli.render_engine_${run} PROPERTIES FIXTURES_SETUP render_${run})
endforeach()
add_test(NAME cli.render_engine_png
         COMMAND ${CMAKE_COMMAND} -DPNG=${out}/render_first.png -DWIDTH=160 -DHEIGHT=120
                 -P ${CMAKE_CURRENT_SOURCE_DIR}/check_png.cmake)
set_tests_properties(cli.render_engine_png PROPERTIES FIXTURES_REQUIRED render_first)
add_test(NAME cli.render_engine_same_bytes
         COMMAND ${CMAKE_COMMAND} -E compare_files ${out}/render_first.png
                 ${out}/render_second.png)
set_tests_properties(cli.render_engine_same_bytes PROPERTIES
                     FIXTURES_REQUIRED "render_first;render_second")
dovetail_cli_test(render_obj EXIT 0
                  ARGS render ${cube} --out ${out}/render_cube.png --width 33 --height 17
                       --camera auto
                  STDOUT "\"parts\":1&&\"triangles\":12" REMOVE ${out}/render_cube.png)

# ---- bad input, unwritable output: exit 1, the file named
dovetail_cli_test(render_missing_input EXIT 1
                  ARGS render ${data}/missing.glb --out ${out}/render_missing.png
                  STDERR "^dovetail: [^\n]*missing.glb: file not found")
dovetail_cli_test(render_bad_input EXIT 1
                  ARGS render ${data}/nan_vertex.obj --out ${out}/render_nan.png
                  STDERR "^dovetail: [^\n]*nan_vertex.obj: [^\n]*not finite")
file(WRITE ${out}/render_file_in_the_way "")
dovetail_cli_test(render_unwritable_out EXIT 1
                  ARGS render ${cube} --out ${out}/render_file_in_the_way/image.png
                  STDERR "^dovetail: [^\n]*render_file_in_the_way/image.png: cannot be written: the folder [^\n]* cannot be made")
dovetail_cli_test(render_into_a_missing_folder EXIT 0
                  ARGS render ${cube} --out ${out}/render_made_folder/deeper/image.png
                  FILE ${out}/render_made_folder/deeper/image.png MATCHES "^.PNG"
                  REMOVE ${out}/render_made_folder)
dovetail_cli_test(render_out_is_directory EXIT 1
                  ARGS render ${cube} --out ${out}
                  STDERR "cli_out: cannot be written: is a directory")

# ---- usage errors: exit 2
dovetail_cli_test(render_missing_out EXIT 2 ARGS render ${cube} STDERR "missing --out")
dovetail_cli_test(render_no_input EXIT 2 ARGS render --out ${out}/render_none.png
                  STDERR "expected one mesh or assembly file")
dovetail_cli_test(render_zero_width EXIT 2
                  ARGS render ${cube} --out ${out}/render_zero.png --width 0 STDERR "--width")
dovetail_cli_test(render_huge_height EXIT 2
                  ARGS render ${cube} --out ${out}/render_huge.png --height 16385 STDERR "--height")
dovetail_cli_test(render_unknown_camera EXIT 2
                  ARGS render ${cube} --out ${out}/render_cam.png --camera overview
                  STDERR "no camera named 'overview'&&views: front, back, right, left, top")
# ---- cameras: the file's own (listed by inspect) and the built-in views
dovetail_cli_test(render_file_camera EXIT 0
                  ARGS render ${render_engine} --out ${out}/render_file_camera.png --width 64
                       --height 48 --camera nodes[81]
                  STDOUT "\"camera\":\"nodes\\[81\\]\"" REMOVE ${out}/render_file_camera.png)
dovetail_cli_test(render_view_top EXIT 0
                  ARGS render ${cube} --out ${out}/render_top.png --width 33 --height 17
                       --camera top
                  STDOUT "\"camera\":\"top\"" REMOVE ${out}/render_top.png)
dovetail_cli_test(inspect_lists_cameras EXIT 0
                  ARGS inspect ${render_engine} --method obb --json
                  STDOUT "\"cameras\":\\[\"nodes\\[81\\]\"\\]")
dovetail_cli_test(render_out_is_input EXIT 2 ARGS render ${cube} --out ${data}/../data/cube.obj
                  STDERR "would be overwritten")
file(COPY ${CMAKE_SOURCE_DIR}/assets/glove/reach_engine.plan DESTINATION ${out})
dovetail_cli_test(render_out_is_plan EXIT 2
                  ARGS render ${cube} --plan ${out}/reach_engine.plan --out ${out}/reach_engine.plan
                  STDERR "would be overwritten")

# A picture that cannot be written to a device fails, and the device stays
# (a partial file is removed only when it is a regular file).
add_test(NAME cli.render_to_a_full_device
         COMMAND sh -c "[ -c /dev/full ] || exit 77; \"$0\" render \"$1\" --width 8 --height 8 --out /dev/full; code=$?; [ -c /dev/full ] || { echo '/dev/full was replaced'; exit 1; }; [ $code -eq 1 ]"
                 $<TARGET_FILE:dovetail> ${data}/cube.obj)
set_tests_properties(cli.render_to_a_full_device PROPERTIES SKIP_RETURN_CODE 77)

# ---- a scenario's frame: the run up to --time, drawn as `run --render` draws it
set(render_peg ${PROJECT_SOURCE_DIR}/scenarios/01_peg_in_hole.lua)
dovetail_cli_test(render_scenario_frame EXIT 0
                  ARGS render ${render_peg} --out ${out}/render_peg.png --time 2 --width 96
                       --height 72
                  STDOUT "\"time\":2,\"frame\":180&&\"camera\":\"scenario\"&&\"hand\":true"
                  FILE ${out}/render_peg.png MATCHES "^.PNG" REMOVE ${out}/render_peg.png)
# The same frame as `run --render DIR --every N` writes: the same bytes.
dovetail_cli_test(render_scenario_run_frames EXIT 0
                  ARGS run ${render_peg} --render ${out}/render_peg_run --every 90 --quiet
                  REMOVE ${out}/render_peg_run)
dovetail_cli_test(render_scenario_run_size EXIT 0
                  ARGS render ${render_peg} --out ${out}/render_peg_180.png --time 2 --width 960
                       --height 720
                  STDOUT "\"frame\":180" REMOVE ${out}/render_peg_180.png)
set_tests_properties(cli.render_scenario_run_frames PROPERTIES FIXTURES_SETUP render_peg_run)
set_tests_properties(cli.render_scenario_run_size PROPERTIES FIXTURES_SETUP render_peg_180)
add_test(NAME cli.render_scenario_same_bytes_as_run
         COMMAND ${CMAKE_COMMAND} -E compare_files ${out}/render_peg_run/frame_000180.png
                 ${out}/render_peg_180.png)
set_tests_properties(cli.render_scenario_same_bytes_as_run PROPERTIES
                     FIXTURES_REQUIRED "render_peg_run;render_peg_180")
# A trace replayed, a built-in view, a frame between two frames' times.
dovetail_cli_test(render_scenario_trace EXIT 0
                  ARGS render ${render_peg} --out ${out}/render_peg_trace.png --width 32 --height 24
                       --trace ${PROJECT_SOURCE_DIR}/assets/traces/peg_in_hole.csv --time 1.005
                       --camera top
                  STDOUT "\"time\":1.0111&&\"frame\":91&&\"camera\":\"top\""
                  REMOVE ${out}/render_peg_trace.png)
dovetail_cli_test(render_scenario_past_its_end EXIT 1
                  ARGS render ${render_peg} --out ${out}/render_peg_late.png --time 200
                  STDERR "01_peg_in_hole.lua: no frame at t=200.000 s: the run's last frame is at t=3.600 s \\(the end of its glove's plan, and a second for the hand to come to rest\\)")
dovetail_cli_test(render_scenario_script_error EXIT 1
                  ARGS render ${data}/scenarios/hostile/endless_custom_action.lua
                       --out ${out}/render_endless.png --time 0.8
                  STDERR "endless_custom_action.lua:5: instruction budget [^\n]* exceeded \\(at t=0.511 s\\)")
dovetail_cli_test(render_scenario_units EXIT 2
                  ARGS render ${render_peg} --out ${out}/render_peg_mm.png --units mm
                  STDERR "--units does not go with a scenario")
dovetail_cli_test(render_scenario_over_itself EXIT 2
                  ARGS render ${render_peg} --out ${render_peg} STDERR "would be overwritten")

# `run --render DIR` removes the frames an earlier run left in DIR (a
# shorter run's frames are not mixed with them), and nothing else.
add_test(NAME cli.run_render_removes_old_frames
         COMMAND sh -c "rm -rf \"$1\" && mkdir -p \"$1\" && touch \"$1/frame_009999.png\" \"$1/mine.png\" && \"$0\" run \"$2\" --render \"$1\" --every 1000 --quiet 2> \"$1.err\" && [ ! -e \"$1/frame_009999.png\" ] && [ -e \"$1/mine.png\" ] && [ -e \"$1/frame_000000.png\" ] && grep -q 'removed 1 frame an earlier run left in' \"$1.err\""
                 $<TARGET_FILE:dovetail> ${out}/render_old_frames ${PROJECT_SOURCE_DIR}/scenarios/04_stacked_bricks.lua)
dovetail_cli_test(render_scenario_failed_before EXIT 1
                  ARGS render ${data}/scenarios/failing/rule_fails.lua --out ${out}/render_failed.png
                       --time 1
                  STDERR "rule_fails.lua: no frame at t=1.000 s: [^\n]*rule_fails.lua:4: a rule failed the run at t=0.500 s: stop here")
dovetail_cli_test(run_render_every_zero EXIT 2
                  ARGS run ${PROJECT_SOURCE_DIR}/scenarios/04_stacked_bricks.lua --render ${out}/every_zero --every 0
                  STDERR "run: --every must be a positive integer \\(every N-th frame\\), not '0'")
dovetail_cli_test(run_render_every_negative EXIT 2
                  ARGS run ${PROJECT_SOURCE_DIR}/scenarios/04_stacked_bricks.lua --render ${out}/every_negative --every -5
                  STDERR "run: --every must be a positive integer \\(every N-th frame\\), not '-5'")
# ... but not when the run is refused: the old frames stay.
add_test(NAME cli.run_render_keeps_old_frames_when_refused
         COMMAND sh -c "rm -rf \"$1\" && mkdir -p \"$1/report_is_a_folder\" && touch \"$1/frame_009999.png\" && \"$0\" run \"$2\" --render \"$1\" --every 1000 --report \"$1/report_is_a_folder\" --quiet 2> /dev/null; [ $? -eq 1 ] && [ -e \"$1/frame_009999.png\" ]"
                 $<TARGET_FILE:dovetail> ${out}/render_refused_frames ${PROJECT_SOURCE_DIR}/scenarios/04_stacked_bricks.lua)
dovetail_cli_test(render_quiet EXIT 0 ARGS render ${cube} --out ${out}/render_quiet.png --width 16 --height 12 --quiet
                  REJECT_STDOUT ".")
