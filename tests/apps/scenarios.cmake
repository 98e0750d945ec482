# ---- scenarios: run, replay, check, new, regress, reference

set(scenarios ${PROJECT_SOURCE_DIR}/scenarios)
set(scenario_data ${data}/scenarios)

# Every shipped scenario is a test of its own.
file(GLOB shipped_scenarios CONFIGURE_DEPENDS ${scenarios}/*.lua)
foreach(file ${shipped_scenarios})
  get_filename_component(stem ${file} NAME_WE)
  dovetail_cli_test(scenario_${stem} EXIT 0 ARGS run ${file} --quiet)
endforeach()

# The README's run: the first shipped scenario, its report and final frame.
dovetail_cli_test(run_default EXIT 0 ARGS run --report ${out}/run_default.json --render ${out}/run_default
                  STDOUT "Peg in hole: passed&&final frame: "
                  FILE ${out}/run_default.json MATCHES "\"outcome\": \"passed\"&&\"state_hash\""
                  REMOVE ${out}/run_default.json)
add_test(NAME cli.run_default_png
         COMMAND ${CMAKE_COMMAND} -DPNG=${out}/run_default/final.png -DWIDTH=960 -DHEIGHT=720
                 -P ${CMAKE_CURRENT_SOURCE_DIR}/check_png.cmake)
set_tests_properties(cli.run_default PROPERTIES FIXTURES_SETUP run_default)
set_tests_properties(cli.run_default_png PROPERTIES FIXTURES_REQUIRED run_default)

# Record, then replay: the same report.
dovetail_cli_test(run_record EXIT 0 ARGS run ${scenarios}/01_peg_in_hole.lua --record ${out}/peg.csv
                  --report ${out}/peg_recorded.json --quiet)
dovetail_cli_test(replay_recorded EXIT 0
                  ARGS replay ${scenarios}/01_peg_in_hole.lua ${out}/peg.csv --threads 2
                       --report ${out}/peg_replayed.json --quiet)
set_tests_properties(cli.run_record PROPERTIES FIXTURES_SETUP peg_recorded)
set_tests_properties(cli.replay_recorded PROPERTIES FIXTURES_SETUP peg_replayed FIXTURES_REQUIRED peg_recorded)
add_test(NAME cli.replay_same_report
         COMMAND ${CMAKE_COMMAND} -E compare_files ${out}/peg_recorded.json ${out}/peg_replayed.json)
set_tests_properties(cli.replay_same_report PROPERTIES FIXTURES_REQUIRED "peg_recorded;peg_replayed")
dovetail_cli_test(replay_missing_trace EXIT 1 ARGS replay ${scenarios}/01_peg_in_hole.lua ${out}/no_such.csv
                  --report ${out}/missing_trace.json STDERR "no_such.csv: file not found"
                  FILE ${out}/missing_trace.json
                  MATCHES "\"outcome\": \"error\"&&\"error\": \".*no_such.csv: file not found\""
                  REMOVE ${out}/missing_trace.json)
dovetail_cli_test(run_missing_scenario EXIT 1 ARGS run ${out}/no_such.lua --report ${out}/missing.json
                  STDERR "no_such.lua: file not found" FILE ${out}/missing.json
                  MATCHES "\"outcome\": \"error\"&&\"state_hash\": null" REMOVE ${out}/missing.json)

# check and new
dovetail_cli_test(check_shipped EXIT 0 ARGS check ${scenarios}/01_peg_in_hole.lua
                  STDOUT "ok: 'Peg in hole', 2 parts, 1 mate, 1 step, 3 rules, 5 expectations, a hand")
dovetail_cli_test(check_syntax_error EXIT 1 ARGS check ${scenario_data}/hostile/syntax_error.lua
                  STDERR "syntax_error.lua:2: ")
dovetail_cli_test(check_missing EXIT 1 ARGS check ${out}/no_such.lua STDERR "no_such.lua: no such file")
dovetail_cli_test(new_scenario EXIT 0 ARGS new my_first --out ${out}/my_first.lua
                  STDOUT "wrote .*my_first.lua" REMOVE ${out}/my_first.lua)
set_tests_properties(cli.new_scenario PROPERTIES FIXTURES_SETUP new_scenario)
dovetail_cli_test(new_scenario_name_with_a_blank EXIT 0 ARGS new "my part" --out "${out}/my part.lua"
                  STDOUT "try 'dovetail check \"[^\"]*my part.lua\"', then 'dovetail run \""
                  REMOVE "${out}/my part.lua")
dovetail_cli_test(new_folder_name EXIT 2 ARGS new ${out}/a_folder/ STDERR "new: the name .*a_folder/. names no file")
string(REPEAT "x" 300 long_name)
dovetail_cli_test(new_name_too_long EXIT 1 ARGS new ${out}/${long_name}
                  STDERR "^dovetail: .*xxx.lua: File name too long\n$")
dovetail_cli_test(regress_short_option_twice EXIT 2 ARGS regress ${out} -j 2 -j 3
                  STDERR "regress: option '-j' given twice")
dovetail_cli_test(new_scenario_checks EXIT 0 ARGS check ${out}/my_first.lua STDOUT "ok: 'my_first'")
dovetail_cli_test(new_scenario_runs EXIT 0 ARGS run ${out}/my_first.lua STDOUT "my_first: passed")
dovetail_cli_test(new_refuses_to_overwrite EXIT 1 ARGS new x --out ${scenarios}/01_peg_in_hole.lua
                  STDERR "exists; not overwritten")
set_tests_properties(cli.new_scenario_checks cli.new_scenario_runs PROPERTIES FIXTURES_REQUIRED new_scenario)
# "new peg.lua" is the scenario peg in peg.lua; its comments name the file as written.
file(MAKE_DIRECTORY ${out}/new_named)
add_test(NAME cli.new_with_the_extension
         COMMAND ${CMAKE_COMMAND} -DPROGRAM=$<TARGET_FILE:dovetail> "-DARGS=new|peg.lua" -DEXPECT_EXIT=0
                 "-DEXPECT_STDOUT=wrote peg.lua;" -DEXPECT_FILE=${out}/new_named/peg.lua
                 "-DEXPECT_FILE_MATCHES=dovetail check peg.lua &&name = \"peg\"" -DREMOVE_FIRST=${out}/new_named/peg.lua
                 -P ${CMAKE_CURRENT_SOURCE_DIR}/check_command.cmake
         WORKING_DIRECTORY ${out}/new_named)
dovetail_cli_test(new_quotes_in_the_name EXIT 0 ARGS new "a\"b" --out ${out}/new_named/quoted.lua
                  FILE ${out}/new_named/quoted.lua MATCHES "name = \"a\\\\\"b\"&&dovetail check .*quoted.lua"
                  REMOVE ${out}/new_named/quoted.lua)
dovetail_cli_test(new_placeholder_in_the_path EXIT 0 ARGS new x --out ${out}/new_named/MYNAME.lua
                  FILE ${out}/new_named/MYNAME.lua MATCHES "dovetail check .*/MYNAME.lua &&name = \"x\""
                  REMOVE ${out}/new_named/MYNAME.lua)
dovetail_cli_test(new_into_a_missing_folder EXIT 0 ARGS new x --out ${out}/new_made_folder/deeper/x.lua
                  FILE ${out}/new_made_folder/deeper/x.lua MATCHES "name = \"x\""
                  REMOVE ${out}/new_made_folder)
file(WRITE ${out}/a_file_in_the_way "")
dovetail_cli_test(new_into_a_folder_that_is_a_file EXIT 1 ARGS new x --out ${out}/a_file_in_the_way/x.lua
                  STDERR "cannot be written: the folder .*a_file_in_the_way cannot be made")

# check reads the glove's plan or trace as the run does: a wrong line is named.
file(WRITE ${out}/check_plan/bad.plan "start 0 0.1 0 1 0 0 0 power\nreach 2.0 0 0.06\n")
file(WRITE ${out}/check_plan/bad_plan.lua
     "return scenario { name = \"bad plan\", parts = { b = part { shape = box { size = { 1, 1, 1 } } } },\n"
     "  hand = glove { plan = \"bad.plan\" } }\n")
dovetail_cli_test(check_reads_the_plan EXIT 1 ARGS check ${out}/check_plan/bad_plan.lua
                  STDERR "bad_plan.lua:2: glove: .*bad.plan:2: reach expects DURATION X Y Z QW QX QY QZ, found 3 fields")
# A glove lasting longer than a run may is refused, by check and by the run, whose report says why.
file(WRITE ${out}/check_plan/long.plan "start 0 0.1 0 1 0 0 0 power\nwait 1e12\n")
file(WRITE ${out}/check_plan/long_plan.lua
     "return scenario { name = \"long plan\", parts = { b = part { shape = box { size = { 1, 1, 1 } } } },\n"
     "  hand = glove { plan = \"long.plan\" },\n"
     "  steps = { step { \"lift\", \"Lift it\", done = after(0.5) } } }\n")
dovetail_cli_test(check_plan_too_long EXIT 1 ARGS check ${out}/check_plan/long_plan.lua
                  STDERR "long_plan.lua:2: glove: .*long.plan: the plan ends at t=1e\\+12 s, later than the 3600.000 s a run may last; a scenario's duration \\(at most 3600.000 s\\) replays its first part only")
dovetail_cli_test(run_plan_too_long EXIT 1 ARGS run ${out}/check_plan/long_plan.lua --report ${out}/check_plan/long.json
                  STDERR "the plan ends at t=1e\\+12 s"
                  REJECT_STDOUT "step "
                  FILE ${out}/check_plan/long.json MATCHES "\"outcome\": \"error\"&&later than the 3600.000 s")
add_test(NAME cli.replay_final_frame_cannot_be_drawn
         COMMAND sh ${CMAKE_CURRENT_SOURCE_DIR}/render_failure.sh $<TARGET_FILE:dovetail>
                 ${scenarios}/06_peg_replay.lua ${PROJECT_SOURCE_DIR}/assets/traces/peg_in_hole.csv
                 ${out}/render_failure)
# A plan written in millimetres reads as metres: the run passes but says the hand is far away.
file(WRITE ${out}/check_plan/mm.plan "start 0 150 0 1 0 0 0 power\nreach 1 0 100 0 1 0 0 0\n")
file(WRITE ${out}/check_plan/mm_plan.lua
     "return scenario { name = \"mm plan\", parts = { b = part { shape = box { size = { 40, 40, 40 } } } },\n"
     "  hand = glove { plan = \"mm.plan\", holding = \"b\" } }\n")
dovetail_cli_test(run_plan_in_millimetres EXIT 0 ARGS run ${out}/check_plan/mm_plan.lua --quiet
                  STDERR "mm_plan.lua:2: glove: the hand is 1.5e\\+05 mm from every part at t=0.000 s; plans and traces are in metres&&mm_plan.lua:2: glove: the hand starts .* from 'b', which it holds")
# Two convex bars laid crosswise 8 mm into each other: no vertex is inside the
# other, and the exact penetration depth says 8 mm.
file(WRITE ${out}/crossed_bars/crossed_bars.lua
     "return scenario { name = \"crossed bars\", duration = 0.1,\n"
     "  parts = { a = part { shape = box { size = { 100, 10, 10 } }, fixed = true },\n"
     "            b = part { shape = box { size = { 10, 10, 100 } }, at = { 0, 2, 0 } } },\n"
     "  expect = { max_penetration(0.01) } }\n")
dovetail_cli_test(run_crossed_bars_penetrate EXIT 3 ARGS run ${out}/crossed_bars/crossed_bars.lua --quiet
                  STDERR "expectation max_penetration\\(0.01\\) failed: 'a' and 'b' overlapped 8 mm at t=0.000 s")
# --record needs a glove to record.
dovetail_cli_test(run_record_without_a_glove EXIT 1
                  ARGS run ${out}/regress_clash/a.lua --record ${out}/check_plan/none.csv
                  STDERR "a.lua: --record: the scenario has no glove, so there are no samples to record")

# Scenarios that should fail say which expectation, when, with which parts.
dovetail_cli_test(fails_mate_impossible EXIT 3 ARGS run ${scenario_data}/failing/mate_impossible.lua --quiet
                  STDERR "expectation mate_made\\(\"peg_in_hole\"\\) failed: 'peg' never snapped into 'block'&&expectation steps_in_order")
dovetail_cli_test(fails_step_out_of_order EXIT 3 ARGS run ${scenario_data}/failing/step_out_of_order.lua --quiet
                  STDERR "expectation steps_in_order\\({ .inspect., .insert. }\\) failed: step 'insert' was completed at t=[0-9.]+ s, before step 'inspect' \\(t=3.000 s\\)")
dovetail_cli_test(fails_pushed_through EXIT 3 ARGS run ${scenario_data}/failing/pushed_through.lua --quiet
                  STDERR "expectation max_penetration\\(0.01\\) failed: 'block' and 'cover' overlapped [0-9.]+ mm at t=[0-9.]+ s")

# regress: hostile scripts end with clear errors, the others still run, every report is written.
dovetail_cli_test(regress_hostile EXIT 3
                  ARGS regress ${scenario_data}/hostile --out ${out}/hostile -j 2 --junit ${out}/hostile.xml
                  STDOUT "PASS +well_behaved&&ERROR +infinite_loop .*instruction budget&&ERROR +string_rep .*string.rep&&ERROR +memory_bomb .*memory&&ERROR +deep_recursion .*stack overflow&&ERROR +coroutine_loop .*instruction budget&&ERROR +os_exit .*'os'&&ERROR +io_open .*'io'&&ERROR +require_module .*'require'&&ERROR +package_loadlib .*'package'&&ERROR +debug_sethook .*'debug'&&ERROR +binary_chunk .*binary chunk&&ERROR +setmetatable_G .*protected metatable&&ERROR +syntax_error .*syntax_error.lua:2:&&ERROR +pcall_swallow .*instruction budget&&ERROR +endless_custom_action .*endless_custom_action.lua:5: .*instruction budget&&ERROR +pattern_backtracking .*pattern_backtracking.lua:4: string.find: the pattern&&1 of 17 scenarios passed"
                  FILE ${out}/hostile.xml MATCHES "tests=\"17\" failures=\"0\" errors=\"16\"")
set_tests_properties(cli.regress_hostile PROPERTIES FIXTURES_SETUP regress_hostile)
add_test(NAME cli.regress_hostile_reports_written
         COMMAND ${CMAKE_COMMAND} -DDIR=${out}/hostile -DCOUNT=17 -P ${CMAKE_CURRENT_SOURCE_DIR}/count_reports.cmake)
set_tests_properties(cli.regress_hostile_reports_written PROPERTIES FIXTURES_REQUIRED regress_hostile)

# A scenario stopped by the timeout still gets its report and a log line saying why.
dovetail_cli_test(regress_timeout EXIT 3
                  ARGS regress ${scenario_data}/slow --out ${out}/slow --timeout 1
                  STDOUT "ERROR +slow .*stopped after the timeout of 1 s"
                  FILE ${out}/slow/slow.json
                  MATCHES "\"outcome\": \"error\"&&stopped after the timeout&&\"simulation\": {&&\"max_penetration\"")

# Outputs are never inputs: not a scenario, not a file a scenario reads (a
# copy of the test data, so that a failing test cannot damage it), not each other.
file(COPY ${scenario_data}/hostile/well_behaved.lua ${scenario_data}/plan_alias DESTINATION ${out}/alias)
dovetail_cli_test(run_report_is_scenario EXIT 2
                  ARGS run ${out}/alias/well_behaved.lua --report ${out}/alias/well_behaved.lua
                  STDERR "would be overwritten")
dovetail_cli_test(run_record_is_report EXIT 2
                  ARGS run ${out}/alias/well_behaved.lua --report ${out}/alias/x.json
                       --record ${out}/alias/x.json
                  STDERR "--report and --record name the same file")
dovetail_cli_test(run_record_is_plan EXIT 1
                  ARGS run ${out}/alias/plan_alias/boxes.lua
                       --record ${out}/alias/plan_alias/hand.plan --report ${out}/alias/kept.json
                  STDERR "hand.plan'[^\n]* is a file the run reads; it would be overwritten"
                  KEEP ${out}/alias/kept.json)
# Nor a folder or a file the run writes: --render's final.png and frames,
# the --render folder itself; refused before the folder is made.
dovetail_cli_test(run_report_is_final_frame EXIT 2
                  ARGS run ${out}/alias/well_behaved.lua --render ${out}/alias/frames
                       --report ${out}/alias/frames/final.png
                  STDERR "--report '.*frames/final.png' is a file that --render .*frames writes")
dovetail_cli_test(run_record_is_a_frame EXIT 2
                  ARGS run ${out}/alias/well_behaved.lua --render ${out}/alias/frames --every 10
                       --record ${out}/alias/frames/frame_000010.png
                  STDERR "--record '.*frame_000010.png' is a file that --render")
dovetail_cli_test(run_report_is_render_folder EXIT 2
                  ARGS run ${out}/alias/well_behaved.lua --render ${out}/alias/same.json
                       --report ${out}/alias/same.json
                  STDERR "--report and --render name the same path"
                  REMOVE ${out}/alias/same.json)
# The report is not written over a mesh the scenario names, even when the
# scenario fails to load, and even when the mesh cannot be read.
file(COPY ${scenario_data}/invalid/mesh_then_error.lua ${data}/cube.obj DESTINATION ${out}/mesh_alias)
dovetail_cli_test(run_report_is_mesh EXIT 1
                  ARGS run ${out}/mesh_alias/mesh_then_error.lua --report ${out}/mesh_alias/cube.obj
                  STDERR "nothing written: the output .*cube.obj.* is a file the run reads"
                  KEEP ${out}/mesh_alias/cube.obj)
# A scenario whose own plan is missing still replays a recorded trace; check says it is missing.
file(COPY ${scenario_data}/plan_alias/boxes.lua DESTINATION ${out}/no_plan)
dovetail_cli_test(run_trace_without_the_plan EXIT 0
                  ARGS run ${out}/no_plan/boxes.lua --trace ${data}/glove/trace_three_samples.csv --quiet)
dovetail_cli_test(check_without_the_plan EXIT 1 ARGS check ${out}/no_plan/boxes.lua
                  STDERR "boxes.lua:6: glove: hand.plan: file not found")
dovetail_cli_test(regress_junit_is_scenario EXIT 2
                  ARGS regress ${out}/alias --out ${out}/alias_out --junit ${out}/alias/well_behaved.lua
                  STDERR "would be overwritten")

# Scenarios that do not load: clear errors naming the file and line.
dovetail_cli_test(check_every_zero EXIT 1 ARGS check ${scenario_data}/invalid/every_zero.lua
                  STDERR "every_zero.lua:5: every: the period must be more than 0 seconds")
dovetail_cli_test(check_missing_plan EXIT 1 ARGS check ${scenario_data}/invalid/missing_plan.lua
                  STDERR "missing_plan.lua:5: glove: no_such.plan: file not found")
# An absolute plan path beside a relative scenario path is named whole.
file(WRITE ${out}/absolute_plan/absolute_plan.lua
     "return scenario { name = \"absolute plan\", parts = { b = part { shape = box { size = { 1, 1, 1 } } } },\n"
     "  hand = glove { plan = \"${out}/absolute_plan/no_such.plan\" } }\n")
add_test(NAME cli.check_absolute_plan_beside_a_relative_scenario
         COMMAND ${CMAKE_COMMAND} -DPROGRAM=$<TARGET_FILE:dovetail> "-DARGS=check|absolute_plan.lua"
                 -DEXPECT_EXIT=1 "-DEXPECT_STDERR=absolute_plan.lua:2: glove: /.*/no_such.plan: file not found"
                 -P ${CMAKE_CURRENT_SOURCE_DIR}/check_command.cmake
         WORKING_DIRECTORY ${out}/absolute_plan)
dovetail_cli_test(check_error_nil EXIT 1 ARGS check ${scenario_data}/invalid/error_nil.lua
                  STDERR "error_nil.lua:3: \\(error object is a nil value\\)")

# Two scenarios whose outputs would be one file are refused before anything runs.
file(WRITE ${out}/regress_clash/a.lua "return scenario { name = \"a\", duration = 0.1, parts = { b = part { shape = box { size = { 1, 1, 1 } } } } }\n")
file(COPY ${out}/regress_clash/a.lua DESTINATION ${out}/regress_clash/more)
file(RENAME ${out}/regress_clash/more/a.lua ${out}/regress_clash/a.log.lua)
dovetail_cli_test(regress_output_names_clash EXIT 1 ARGS regress ${out}/regress_clash --out ${out}/regress_clash_out
                  STDERR "a.log.lua and .*a.lua would both write OUT/a.log; rename one of them")
# Nor a scenario's output over another scenario (--out the scenarios' folder).
file(WRITE ${out}/regress_into_itself/b.lua "return scenario { name = \"b\", duration = 0.1, parts = { b = part { shape = box { size = { 1, 1, 1 } } } } }\n")
file(WRITE ${out}/regress_into_itself/b.lua.lua "return scenario { name = \"b\", duration = 0.1, parts = { b = part { shape = box { size = { 1, 1, 1 } } } } }\n")
dovetail_cli_test(regress_output_is_a_scenario EXIT 2
                  ARGS regress ${out}/regress_into_itself --out ${out}/regress_into_itself
                  STDERR "regress: .*b.lua, an output of .*b.lua.lua, is the scenario .*b.lua; choose another --out")
# A summary is not written over a scenario's report, log or frames.
dovetail_cli_test(regress_junit_is_a_report EXIT 2
                  ARGS regress ${out}/regress_clash --out ${out}/regress_summary_out
                       --junit ${out}/regress_summary_out/a.json
                  STDERR "--junit '.*regress_summary_out/a.json' is an output of .*a.lua in")
dovetail_cli_test(regress_html_is_a_log EXIT 2
                  ARGS regress ${out}/regress_clash --out ${out}/regress_summary_out
                       --html ${out}/regress_summary_out/a.log
                  STDERR "--html '.*a.log' is an output of")
dovetail_cli_test(regress_junit_is_the_out_folder EXIT 2
                  ARGS regress ${out}/regress_clash --out ${out}/regress_summary_out
                       --junit ${out}/regress_summary_out
                  STDERR "--junit '.*regress_summary_out' is the output folder")
dovetail_cli_test(regress_html_is_a_frames_folder EXIT 2
                  ARGS regress ${out}/regress_clash --out ${out}/regress_summary_out
                       --html ${out}/regress_summary_out/a
                  STDERR "--html '.*regress_summary_out/a' is an output of .*a.lua in")
# A folder whose name starts with '-', a link to a missing scenario (named, not
# skipped), and a report that is UTF-8 whatever bytes the scenario's error holds.
file(WRITE ${out}/regress_odd/-dash/ok.lua "return scenario { name = \"ok\", duration = 0.1, parts = { b = part { shape = box { size = { 1, 1, 1 } } } } }\n")
file(WRITE ${out}/regress_odd/-dash/not_utf8.lua "error(\"bad \\255\\254\")\n")
file(CREATE_LINK ${out}/regress_odd/no_such_file.lua ${out}/regress_odd/-dash/broken.lua SYMBOLIC)
add_test(NAME cli.regress_odd_names
         COMMAND ${CMAKE_COMMAND} -DPROGRAM=$<TARGET_FILE:dovetail>
                 "-DARGS=regress|--out|odd_out|--html|odd.html|--|-dash" -DEXPECT_EXIT=3
                 "-DEXPECT_STDOUT=ERROR +broken .*broken.lua: file not found&&ERROR +not_utf8 &&PASS +ok"
                 -DEXPECT_FILE=${out}/regress_odd/odd_out/not_utf8.json "-DEXPECT_FILE_MATCHES=bad ��"
                 -P ${CMAKE_CURRENT_SOURCE_DIR}/check_command.cmake
         WORKING_DIRECTORY ${out}/regress_odd)
# The HTML report shows each scenario's messages: a rule's log and warn, with time and line.
file(WRITE ${out}/regress_messages/in/talks.lua "return scenario { name = \"talks\", duration = 0.2,
  parts = { b = part { shape = box { size = { 1, 1, 1 } } } },
  rules = { rule { when = after(0.1), act = { log \"half way\", warn \"mind the gap\" } } },
}\n")
dovetail_cli_test(regress_html_messages EXIT 0
                  ARGS regress ${out}/regress_messages/in --out ${out}/regress_messages/out
                       --html ${out}/regress_messages/report.html
                  FILE ${out}/regress_messages/report.html
                  MATCHES "<td>0.1[0-9]*</td><td>log</td><td>half way</td><td>.*talks.lua:3</td>&&<td class=\"failed\">warn</td><td>mind the gap</td>")
dovetail_cli_test(regress_shard_too_large EXIT 2 ARGS regress ${scenarios} --shard 1/18446744073709551618
                  STDERR "--shard must be K/N")
add_test(NAME cli.regress_interrupted
         COMMAND sh ${CMAKE_CURRENT_SOURCE_DIR}/regress_interrupt.sh $<TARGET_FILE:dovetail>
                 ${out}/regress_interrupted)
set_tests_properties(cli.regress_interrupted PROPERTIES TIMEOUT 300)
add_test(NAME cli.regress_stale_outputs
         COMMAND sh ${CMAKE_CURRENT_SOURCE_DIR}/regress_stale.sh $<TARGET_FILE:dovetail>
                 ${scenarios} ${out}/regress_stale)

add_test(NAME cli.regress_baseline
         COMMAND sh ${CMAKE_CURRENT_SOURCE_DIR}/regress_baseline.sh $<TARGET_FILE:dovetail>
                 ${scenarios} ${out}/regress_baseline)
dovetail_cli_test(regress_baseline_is_out EXIT 2
                  ARGS regress ${scenarios} --baseline ${out} --out ${out}
                  STDERR "--baseline [^\n]* is the output folder")
dovetail_cli_test(regress_baseline_missing EXIT 1
                  ARGS regress ${scenarios} --baseline ${out}/no_such_baseline
                  STDERR "no_such_baseline: no such folder \\(make a baseline with")
dovetail_cli_test(regress_baseline_tolerance_alone EXIT 2
                  ARGS regress ${scenarios} --baseline-tolerance 0.1
                  STDERR "--baseline-tolerance needs --baseline")
dovetail_cli_test(regress_bad_jobs EXIT 2 ARGS regress ${scenarios} -j 0 STDERR "regress: -j must be an integer from 1 to 256")
file(MAKE_DIRECTORY ${out}/regress_empty_folder)
dovetail_cli_test(regress_empty_folder EXIT 1 ARGS regress ${out}/regress_empty_folder
                  STDERR "regress_empty_folder: no scenarios in this folder")
dovetail_cli_test(regress_empty_shard EXIT 0 ARGS regress ${scenarios} --shard 18/18
                  --out ${out}/regress_empty_shard
                  STDERR "no scenarios in .* for this shard")
dovetail_cli_test(regress_bad_shard EXIT 2 ARGS regress ${scenarios} --shard 3/2 STDERR "--shard must be K/N")
dovetail_cli_test(regress_not_a_folder EXIT 1 ARGS regress ${out}/no_such_folder STDERR "not a folder")
dovetail_cli_test(regress_a_scenario EXIT 1 ARGS regress ${scenarios}/01_peg_in_hole.lua
                  STDERR "01_peg_in_hole.lua: not a folder \\(regress runs every scenario of a folder; 'dovetail run [^']*01_peg_in_hole.lua' runs one\\)")
dovetail_cli_test(regress_baseline_is_scenarios EXIT 1
                  ARGS regress ${scenarios} --baseline ${scenarios}
                  STDERR "holds no report of a scenario in [^\n]*--out [^\n]*baseline', a folder of its own, then give it as --baseline\\)")
dovetail_cli_test(replay_a_plan EXIT 1
                  ARGS replay ${scenarios}/01_peg_in_hole.lua ${PROJECT_SOURCE_DIR}/assets/glove/peg_in_hole.plan
                  STDERR "peg_in_hole.plan is a glove plan, which a scenario names as glove \\{ plan = \"...\" \\}; a trace, as replay, --trace and glove \\{ trace = \"...\" \\} take, is a recorded CSV file")

# The shipped scenarios: every one passes, the same reports at 1, 2 and 8 threads, twice.
add_test(NAME cli.regress_shipped_deterministic
         COMMAND ${CMAKE_COMMAND} -DPROGRAM=$<TARGET_FILE:dovetail> -DSCENARIOS=${scenarios}
                 -DOUT=${out}/regress_shipped -P ${CMAKE_CURRENT_SOURCE_DIR}/regress_determinism.cmake)
set_tests_properties(cli.regress_shipped_deterministic PROPERTIES TIMEOUT 1800 FIXTURES_SETUP regress_shipped)

# The HTML report opens in a real headless browser; its screenshot is kept for a look by eye.
find_program(DOVETAIL_CHROMIUM NAMES chromium chromium-browser)
if(DOVETAIL_CHROMIUM)
  add_test(NAME cli.regress_html_in_browser
           COMMAND ${CMAKE_COMMAND} -DCHROMIUM=${DOVETAIL_CHROMIUM} -DHTML=${out}/regress_shipped/1/report.html
                   -DSHOT=${out}/regress_report.png -P ${CMAKE_CURRENT_SOURCE_DIR}/html_in_browser.cmake)
  set_tests_properties(cli.regress_html_in_browser PROPERTIES FIXTURES_REQUIRED regress_shipped TIMEOUT 300)
endif()

# The reference in docs/authoring.md is the vocabulary's own.
add_test(NAME cli.reference_matches_docs
         COMMAND ${CMAKE_COMMAND} -DPROGRAM=$<TARGET_FILE:dovetail> -DDOC=${PROJECT_SOURCE_DIR}/docs/authoring.md
                 -P ${CMAKE_CURRENT_SOURCE_DIR}/reference_in_docs.cmake)

# A glove plan that is missing: the error names the scenario's line and the file.
file(WRITE ${out}/missing_plan.lua "return scenario {\n  name = \"x\", duration = 1,\n  parts = { a = part { shape = box { size = { 1, 1, 1 } } } },\n  hand = glove { plan = \"no_such.plan\" },\n}\n")
dovetail_cli_test(run_missing_plan EXIT 1 ARGS run ${out}/missing_plan.lua --quiet
                  STDERR "missing_plan.lua:4: glove: .*no_such.plan")

# The open hand drawn back along a part that has just snapped: it once grasped
# the part again (and then crashed on a blocked slide with no contact). An open,
# still hand grasps nothing now; the scenario's rule warns if it does.
dovetail_cli_test(regrasp_after_snap EXIT 0 ARGS run ${scenario_data}/regrasp/regrasp_after_snap.lua --quiet)

# ---- failure capture
# A shipped scenario cross-checked with another method: nothing suspect, so no
# warning and no capture file (the folder stays empty).
dovetail_cli_test(run_capture_cross_check EXIT 0
                  ARGS run ${scenarios}/01_peg_in_hole.lua --quiet --capture ${out}/captures
                       --cross-check dop18
                  STDERR "^$")
# Without --quiet, the summary says the capture looked and found nothing.
dovetail_cli_test(run_capture_clean_said EXIT 0
                  ARGS run ${scenarios}/01_peg_in_hole.lua --capture ${out}/captures_said
                       --cross-check dop18
                  STDOUT "  capture: no suspect collision query, every exact pair cross-checked\n")
dovetail_cli_test(run_cross_check_needs_capture EXIT 2
                  ARGS run ${scenarios}/01_peg_in_hole.lua --cross-check dop18
                  STDERR "--cross-check needs --capture DIR")
dovetail_cli_test(run_cross_check_unknown EXIT 2
                  ARGS run ${scenarios}/01_peg_in_hole.lua --capture ${out}/captures --cross-check fcl
                  STDERR "unknown --cross-check method 'fcl'")
dovetail_cli_test(capture_replay_checked_in EXIT 0
                  ARGS capture ${data}/captures/resting-boxes-turned.capture
                       ${data}/captures/touching-hulls.capture
                  STDOUT "methods-disagree not reproduced: every method says intersecting&&iteration-cap not reproduced")
file(WRITE ${out}/empty.capture "")
dovetail_cli_test(capture_empty_file EXIT 1 ARGS capture ${out}/empty.capture STDERR "empty.capture: empty")
dovetail_cli_test(capture_bad_file EXIT 1 ARGS capture ${data}/cube.obj
                  STDERR "cube.obj:1: not a capture file")
# An unreadable file is said, and the files after it are replayed all the same.
dovetail_cli_test(capture_bad_files_and_a_good_one EXIT 1
                  ARGS capture ${out}/no_such.capture ${data} ${data}/captures/touching-hulls.capture
                  STDERR "no_such.capture: cannot be opened&&/data: no .capture files in this folder"
                  STDOUT "touching-hulls.capture: iteration-cap not reproduced")
# A folder: its capture files in name order.
dovetail_cli_test(capture_replay_folder EXIT 0 ARGS capture ${data}/captures
                  STDOUT "^[^\n]*resting-boxes-turned.capture: methods-disagree not reproduced[^\n]*\n[^\n]*touching-hulls.capture: iteration-cap not reproduced")
# A one-letter option's value may be joined on, as make's -j2.
dovetail_cli_test(regress_short_option_joined EXIT 2 ARGS regress ${scenarios} -j0
                  STDERR "regress: -j must be an integer from 1 to 256")
dovetail_cli_test(regress_short_option_joined_twice EXIT 2 ARGS regress ${scenarios} -j2 -j 3
                  STDERR "regress: option '-j' given twice")
dovetail_cli_test(regress_short_option_unknown EXIT 2 ARGS regress ${scenarios} -x2
                  STDERR "regress: unknown option '-x2'")
