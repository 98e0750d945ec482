# `dovetail glove` and `dovetail render --trace/--plan`: included from
# CMakeLists.txt, uses its dovetail_cli_test.

set(glove ${data}/glove)
set(engine_glb /usr/share/assimp/models/glTF2/2CylinderEngine-glTF-Binary/2CylinderEngine.glb)

dovetail_cli_test(glove_help EXIT 0 ARGS glove --help
                  STDOUT "^usage: dovetail glove convert&&glove plan&&glove check")
dovetail_cli_test(glove_listed EXIT 0 ARGS --help STDOUT "glove ")
dovetail_cli_test(glove_no_action EXIT 2 ARGS glove STDERR "expected an action")
dovetail_cli_test(glove_unknown_action EXIT 2 ARGS glove frobnicate STDERR "unknown action 'frobnicate'")

# ---- check: a good trace, and every kind of bad one names the file and line, exit 1
dovetail_cli_test(glove_check EXIT 0 ARGS glove check ${glove}/trace_three_samples.csv
                  STDOUT "^{[^\n]*}\n$&&\"action\":\"check\"&&\"samples\":3&&\"rate_hz_median\":90")
# A joint far outside its range (500 degrees): checked, with a warning naming it.
dovetail_cli_test(glove_check_joint_out_of_range EXIT 0
                  ARGS glove check ${glove}/trace_joint_out_of_range.csv
                  STDOUT "\"samples\":3"
                  STDERR "trace_joint_out_of_range.csv: index_mcp reaches 500 deg at t=0.0111111 s, outside its range \\[-30, 90\\] by 410 deg")
# Times in milliseconds read as seconds (a take of a second, 92 samples): read, with a warning.
dovetail_cli_test(glove_check_times_in_milliseconds EXIT 0
                  ARGS glove check ${glove}/trace_times_in_milliseconds.csv
                  STDOUT "\"samples\":92"
                  STDERR "trace_times_in_milliseconds.csv: its samples are 11.11 s apart \\(the median\\), 0.09 samples a second[^\n]*are its times in milliseconds\\?")
# A start on a device clock and positions in millimetres, said as a run would.
dovetail_cli_test(glove_check_device_clock_millimetres EXIT 0
                  ARGS glove check ${glove}/trace_device_clock_millimetres.csv
                  STDOUT "\"samples\":3"
                  STDERR "it starts at t=8123.25 s; a run replays from t = 0[^\n]*shift its times to start at 0\\)\n.*the tracker is 198.494 m from the origin at t=8123.25 s[^\n]*are its positions in millimetres\\?")
# A start before t = 0: what it holds before then is not used, as a run says.
dovetail_cli_test(glove_check_starts_before_zero EXIT 0
                  ARGS glove check ${glove}/trace_starts_before_zero.csv
                  STDOUT "\"samples\":3"
                  STDERR "trace_starts_before_zero.csv: it starts at t=-1 s; a run starts at t = 0, so what it holds before then is not used")
# Joint angles in radians read as degrees: a hand that hardly moves.
dovetail_cli_test(glove_check_joint_angles_in_radians EXIT 0
                  ARGS glove check ${glove}/trace_joint_angles_in_radians.csv
                  STDOUT "\"samples\":4"
                  STDERR "trace_joint_angles_in_radians.csv: no joint angle is beyond \\+-3.14 over the whole take \\(the largest, index_mcp, is 1.2 at t=0.0333333 s\\)[^\n]*are the angles in radians\\? Dovetail reads degrees")
dovetail_cli_test(glove_check_no_final_line_end EXIT 0
                  ARGS glove check ${glove}/trace_no_final_line_end.csv
                  STDOUT "\"samples\":3"
                  STDERR "trace_no_final_line_end.csv: its last line has no line end")
foreach(case
    "missing_column|bad_missing_column.csv:1: missing columns: wrist_yaw"
    "unknown_column|bad_unknown_column.csv:1: unknown column 'elbow'"
    "duplicate_column|bad_duplicate_column.csv:1: duplicated column 'palm_arch'"
    "nan|bad_nan.csv:3: column thumb_roll [^\n]*'nan' is not finite"
    "time_backwards|bad_time_backwards.csv:4: time does not increase"
    "empty|bad_empty.csv: empty, no header"
    "no_header|bad_no_header.csv:1: expected a header row"
    "short_row|bad_short_row.csv:3: expected 30 fields, found 29"
    "tab_separated|trace_tab_separated.csv:1: unknown column [^\n]*; the fields of a trace are separated by commas"
    "cr_line_endings|bad_cr_line_endings.csv:1: a carriage return within the line")
  string(REPLACE "|" ";" parts "${case}")
  list(GET parts 0 name)
  list(GET parts 1 message)
  string(REGEX MATCH "^[a-z_]+\\.csv" file "${message}")
  dovetail_cli_test(glove_check_${name} EXIT 1 ARGS glove check ${glove}/${file}
                    STDERR "^dovetail: [^\n]*${message}" REJECT_STDOUT ".")
endforeach()
dovetail_cli_test(glove_check_missing EXIT 1 ARGS glove check ${glove}/no_such_trace.csv
                  STDERR "no_such_trace.csv: file not found")
# A 1 GiB line (sparse, made at test time) is refused after 64 KiB, not read.
add_test(NAME cli.glove_long_line_setup
         COMMAND sh -c "head -2 '${glove}/trace_three_samples.csv' > '${out}/long_line.csv' && truncate -s 1G '${out}/long_line.csv'")
set_tests_properties(cli.glove_long_line_setup PROPERTIES FIXTURES_SETUP glove_long_line)
dovetail_cli_test(glove_check_long_line EXIT 1 ARGS glove check ${out}/long_line.csv
                  STDERR "long_line.csv:3: line longer than 65536 bytes")
set_tests_properties(cli.glove_check_long_line PROPERTIES FIXTURES_REQUIRED glove_long_line TIMEOUT 30)
add_test(NAME cli.glove_long_line_cleanup COMMAND ${CMAKE_COMMAND} -E rm -f ${out}/long_line.csv)
set_tests_properties(cli.glove_long_line_cleanup PROPERTIES FIXTURES_CLEANUP glove_long_line)

# ---- convert
dovetail_cli_test(glove_convert_cyberglove EXIT 0
                  ARGS glove convert --cyberglove ${glove}/cyberglove_raw.txt
                       --calibration ${glove}/cyberglove_calibration.txt --out ${out}/cyberglove.csv
                  STDOUT "\"action\":\"convert_cyberglove\"&&\"samples\":2"
                  FILE ${out}/cyberglove.csv
                  MATCHES "^t,x,y,z,qw,qx,qy,qz,thumb_roll,&&\n0,0,0.1,0,1,0,0,0,50,50.51,51.04,51.59,"
                  REMOVE ${out}/cyberglove.csv)
dovetail_cli_test(glove_convert_cyberglove_bad_count EXIT 1
                  ARGS glove convert --cyberglove ${glove}/cyberglove_bad_count.txt
                       --calibration ${glove}/cyberglove_calibration.txt --out ${out}/bad_count.csv
                  STDERR "cyberglove_bad_count.txt:2: [^\n]*'256' is outside .0, 255.")
dovetail_cli_test(glove_convert_openxr EXIT 0
                  ARGS glove convert --openxr ${glove}/openxr_three_frames.csv --out ${out}/openxr.csv
                  STDOUT "\"action\":\"convert_openxr\"&&\"samples\":3"
                  FILE ${out}/openxr.csv MATCHES "^t,x,y,z,&&\n0.5,0.1,0.2,-0.3,0.99619469809174[0-9]*,0,0.0871557427476581[0-9]*,0,(60|59.99999)"
                  REMOVE ${out}/openxr.csv)
dovetail_cli_test(glove_convert_openxr_not_openxr EXIT 1
                  ARGS glove convert --openxr ${glove}/trace_three_samples.csv --out ${out}/x.csv
                  STDERR "trace_three_samples.csv:1: unknown column 'x'")
dovetail_cli_test(glove_convert_both EXIT 2
                  ARGS glove convert --openxr a.csv --cyberglove b.txt --out ${out}/x.csv
                  STDERR "give one of --cyberglove RAW or --openxr JOINTS")
dovetail_cli_test(glove_convert_no_calibration EXIT 2
                  ARGS glove convert --cyberglove ${glove}/cyberglove_raw.txt --out ${out}/x.csv
                  STDERR "missing --calibration")
dovetail_cli_test(glove_convert_out_is_input EXIT 2
                  ARGS glove convert --openxr ${glove}/openxr_three_frames.csv
                       --out ${glove}/openxr_three_frames.csv
                  STDERR "would be overwritten")

# ---- plan: a trace at the asked rate, then the hand of that trace drawn over the engine
dovetail_cli_test(glove_plan EXIT 0
                  ARGS glove plan ${PROJECT_SOURCE_DIR}/assets/glove/reach_engine.plan
                       --out ${out}/reach_engine.csv --rate 120
                  STDOUT "\"action\":\"plan\"&&\"samples\":241&&\"duration\":2&&\"rate_hz_median\":120")
set_tests_properties(cli.glove_plan PROPERTIES FIXTURES_SETUP reach_trace)
dovetail_cli_test(glove_plan_noisy EXIT 0
                  ARGS glove plan ${PROJECT_SOURCE_DIR}/assets/glove/reach_engine.plan
                       --out ${out}/reach_noisy.csv --noise --seed 4
                  STDOUT "\"samples\":182,\"start\":0,\"duration\":2.005" REMOVE ${out}/reach_noisy.csv)
# A plan whose end falls between two samples ends with a sample at its end.
file(WRITE ${out}/short_wait.plan "start 0 0 0 1 0 0 0 open\nwait 0.02\n")
dovetail_cli_test(glove_plan_ends_at_the_plans_end EXIT 0
                  ARGS glove plan ${out}/short_wait.plan --out ${out}/short_wait.csv
                  STDOUT "\"samples\":3,\"start\":0,\"duration\":0.02,"
                  FILE ${out}/short_wait.csv MATCHES "\n0.02,0,0,0,1,"
                  REMOVE ${out}/short_wait.csv)
dovetail_cli_test(glove_plan_bad_rate EXIT 2
                  ARGS glove plan ${PROJECT_SOURCE_DIR}/assets/glove/reach_engine.plan
                       --out ${out}/x.csv --rate 0
                  STDERR "--rate must")
dovetail_cli_test(glove_plan_seed_without_noise EXIT 2
                  ARGS glove plan ${PROJECT_SOURCE_DIR}/assets/glove/reach_engine.plan
                       --out ${out}/x.csv --seed 3
                  STDERR "--seed needs --noise")
file(WRITE ${out}/endless.plan "wait 1e300\n")
dovetail_cli_test(glove_plan_endless EXIT 1 ARGS glove plan ${out}/endless.plan --out ${out}/x.csv
                  STDERR "endless.plan: the plan lasts 1e\\+300 s&&at most 10\\^7")
dovetail_cli_test(glove_plan_bad_plan EXIT 1
                  ARGS glove plan ${glove}/trace_three_samples.csv --out ${out}/x.csv
                  STDERR "trace_three_samples.csv:1: ")
if(EXISTS ${engine_glb})
  dovetail_cli_test(render_hand_trace EXIT 0
                    ARGS render ${engine_glb} --trace ${out}/reach_engine.csv --time 1.5
                         --out ${out}/render_hand.png --width 160 --height 120
                    STDOUT "\"hand\":true&&\"parts\":131" REMOVE ${out}/render_hand.png)
  set_tests_properties(cli.render_hand_trace PROPERTIES FIXTURES_REQUIRED reach_trace)
  dovetail_cli_test(render_hand_plan EXIT 0
                    ARGS render ${engine_glb} --plan ${PROJECT_SOURCE_DIR}/assets/glove/reach_engine.plan
                         --time 0.5 --hand-size adult_f05 --out ${out}/render_hand_plan.png
                         --width 160 --height 120
                    STDOUT "\"hand\":true" REMOVE ${out}/render_hand_plan.png)
endif()
dovetail_cli_test(render_hand_bad_trace EXIT 1
                  ARGS render ${cube} --trace ${glove}/bad_nan.csv --out ${out}/x.png
                  STDERR "bad_nan.csv:3: ")
dovetail_cli_test(render_hand_unknown_size EXIT 2
                  ARGS render ${cube} --trace ${glove}/trace_three_samples.csv --hand-size giant
                       --out ${out}/x.png
                  STDERR "unknown size 'giant'")
# The unit of an assembly drawn with a hand: inferred with a note, or given.
dovetail_cli_test(render_hand_units_inferred EXIT 0
                  ARGS render ${cube} --trace ${glove}/trace_three_samples.csv --out ${out}/units.png
                       --width 80 --height 60
                  STDERR "cube.obj: units inferred: largest extent [0-9.]+ file units, read as metres \\(--units mm, cm or m says which\\)"
                  REMOVE ${out}/units.png)
dovetail_cli_test(render_hand_units_given EXIT 0
                  ARGS render ${cube} --trace ${glove}/trace_three_samples.csv --units mm
                       --out ${out}/units_mm.png --width 80 --height 60
                  STDOUT "\"hand\":true" REMOVE ${out}/units_mm.png)
dovetail_cli_test(render_hand_units_unknown EXIT 2
                  ARGS render ${cube} --trace ${glove}/trace_three_samples.csv --units inch
                       --out ${out}/x.png
                  STDERR "--units must be mm, cm or m, not 'inch'")
dovetail_cli_test(render_units_without_hand EXIT 2
                  ARGS render ${cube} --units mm --out ${out}/x.png STDERR "--units needs --trace or --plan")
dovetail_cli_test(render_time_without_trace EXIT 2
                  ARGS render ${cube} --time 1 --out ${out}/x.png STDERR "--time needs --trace or --plan")

# A plan too long to sample is an input error naming it, and writes nothing.
dovetail_cli_test(glove_plan_too_long EXIT 1
                  ARGS glove plan ${data}/glove/too_long.plan --out ${out}/too_long.csv
                  STDERR "too_long.plan: the plan lasts 1e\\+12 s&&at most 10\\^7"
                  REMOVE ${out}/too_long.csv)
dovetail_cli_test(glove_plan_rate_zero EXIT 2
                  ARGS glove plan ${data}/glove/too_long.plan --out ${out}/too_long.csv --rate 0
                  STDERR "--rate must be a number of Hz in \\(0, 100000\\], not '0'")
dovetail_cli_test(glove_plan_rate_not_a_number EXIT 2
                  ARGS glove plan ${data}/glove/too_long.plan --out ${out}/too_long.csv --rate abc
                  STDERR "--rate must be a number of Hz in \\(0, 100000\\], not 'abc'")

# A byte-order mark before the header is not part of the first column's name,
# and a control byte in a bad field is shown escaped, not sent to the terminal.
dovetail_cli_test(glove_check_bom EXIT 0 ARGS glove check ${glove}/trace_with_bom.csv
                  STDOUT "\"samples\":3")
dovetail_cli_test(glove_check_control_byte EXIT 1 ARGS glove check ${glove}/bad_control_byte.csv
                  STDERR "bad_control_byte.csv:2: column y \\(field 3\\): '0.\\\\x0F1' is not a number")
