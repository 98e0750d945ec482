# `dovetail broadphase`: included from CMakeLists.txt, uses its dovetail_cli_test.

set(bp_data ${data}/broadphase)
set(bp_touching_pairs
    "frame 0 count 2\n0 1\n2 3\nframe 1 count 1\n0 3\nframe 2 count 4\n0 1\n0 2\n0 3\n1 2\n")
set(bp_keys
    "\"objects\":4&&\"frames\":3&&\"ms_per_frame_median\":[0-9]&&\"pairs_total\":7")

dovetail_cli_test(broadphase_help EXIT 0 ARGS broadphase --help
                  STDOUT "^usage: dovetail broadphase&&--boxes FILE&&grid&&sap&&octree&&mbp&&brute")
dovetail_cli_test(broadphase_listed EXIT 0 ARGS --help STDOUT "broadphase")

# ---- results: touching boxes, a point, coincident boxes, every method
dovetail_cli_test(broadphase_stdout EXIT 0 ARGS broadphase --boxes ${bp_data}/touching.txt
                  STDOUT "^${bp_touching_pairs}{[^\n]*}\n$&&\"method\":\"grid\"&&${bp_keys}")
foreach(method brute sap grid octree mbp)
  dovetail_cli_test(broadphase_out_${method} EXIT 0
                    ARGS broadphase --boxes ${bp_data}/touching.txt --method ${method}
                         --out ${out}/bp_pairs_${method}.txt
                    STDOUT "^{[^\n]*}\n$&&\"method\":\"${method}\"&&${bp_keys}"
                    FILE ${out}/bp_pairs_${method}.txt CONTENT "${bp_touching_pairs}"
                    REMOVE ${out}/bp_pairs_${method}.txt)
endforeach()

# ---- bad input: error naming file and line, exit 1, the frames before it written
dovetail_cli_test(broadphase_nan EXIT 1
                  ARGS broadphase --boxes ${bp_data}/bad_nan.txt --method sap
                       --out ${out}/bp_pairs_nan.txt
                  STDERR "^dovetail: [^\n]*bad_nan.txt:9: 'nan' is not finite"
                  STDOUT "\"frames\":2&&\"pairs_total\":1&&\"error\":"
                  FILE ${out}/bp_pairs_nan.txt CONTENT "frame 0 count 1\n0 1\nframe 1 count 0\n"
                  REMOVE ${out}/bp_pairs_nan.txt)
dovetail_cli_test(broadphase_truncated EXIT 1
                  ARGS broadphase --boxes ${bp_data}/truncated.txt --out ${out}/bp_pairs_trunc.txt
                  STDERR "truncated.txt:6: file ends in frame 1 after 1 of 3 boxes"
                  STDOUT "\"frames\":1"
                  FILE ${out}/bp_pairs_trunc.txt CONTENT "frame 0 count 1\n0 1\n"
                  REMOVE ${out}/bp_pairs_trunc.txt)
dovetail_cli_test(broadphase_columns EXIT 1 ARGS broadphase --boxes ${bp_data}/bad_columns.txt
                  STDERR "bad_columns.txt:2: expected 6 numbers[^\n]*got 5 fields")
dovetail_cli_test(broadphase_word EXIT 1 ARGS broadphase --boxes ${bp_data}/bad_word.txt
                  STDERR "bad_word.txt:2: 'zero' is not a number")
dovetail_cli_test(broadphase_range EXIT 1 ARGS broadphase --boxes ${bp_data}/bad_range.txt
                  STDERR "bad_range.txt:2: '1e999' is out of range")
dovetail_cli_test(broadphase_min_max EXIT 1 ARGS broadphase --boxes ${bp_data}/bad_min_max.txt
                  STDERR "bad_min_max.txt:3: min > max on axis y")
dovetail_cli_test(broadphase_extra_lines EXIT 1 ARGS broadphase --boxes ${bp_data}/extra_lines.txt
                  STDERR "extra_lines.txt:3: more data than the first line declares"
                  STDOUT "\"frames\":1")
dovetail_cli_test(broadphase_header EXIT 1 ARGS broadphase --boxes ${bp_data}/bad_header.txt
                  STDERR "bad_header.txt:1: expected a first line")
dovetail_cli_test(broadphase_frame_count EXIT 1
                  ARGS broadphase --boxes ${bp_data}/bad_frame_count.txt
                  STDERR "bad_frame_count.txt:1: the frame count F must be a non-negative integer")
# Found by the box_file fuzz target: F was unbounded when frames have no lines.
dovetail_cli_test(broadphase_no_objects EXIT 1 ARGS broadphase --boxes ${bp_data}/no_objects.txt
                  STDERR "no_objects.txt:1: no objects [^\n]*but F > 0 frames")
dovetail_cli_test(broadphase_empty EXIT 1 ARGS broadphase --boxes ${bp_data}/empty.txt
                  STDERR "empty.txt:1: empty file")
dovetail_cli_test(broadphase_missing_file EXIT 1 ARGS broadphase --boxes ${bp_data}/no_such.txt
                  STDERR "no_such.txt: file not found")
dovetail_cli_test(broadphase_directory EXIT 1 ARGS broadphase --boxes ${bp_data}
                  STDERR "is a directory")
file(WRITE ${out}/broadphase_file_in_the_way "")
dovetail_cli_test(broadphase_unwritable_out EXIT 1
                  ARGS broadphase --boxes ${bp_data}/touching.txt
                       --out ${out}/broadphase_file_in_the_way/pairs.txt
                  STDERR "broadphase_file_in_the_way/pairs.txt: cannot be written")

# ---- usage errors
dovetail_cli_test(broadphase_unknown_method EXIT 2
                  ARGS broadphase --boxes ${bp_data}/touching.txt --method boxtree
                  STDERR "unknown method 'boxtree'&&brute, sap, grid, octree, mbp")
dovetail_cli_test(broadphase_missing_boxes EXIT 2 ARGS broadphase STDERR "missing --boxes")
dovetail_cli_test(broadphase_positional EXIT 2
                  ARGS broadphase ${bp_data}/touching.txt --boxes ${bp_data}/touching.txt
                  STDERR "expected no positional arguments")
dovetail_cli_test(broadphase_out_is_input EXIT 2
                  ARGS broadphase --boxes ${bp_data}/touching.txt --out ${bp_data}/../broadphase/touching.txt
                  STDERR "would be overwritten")
