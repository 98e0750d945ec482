# `dovetail query --distance / --tolerance / --contacts`: included from CMakeLists.txt,
# uses its dovetail_cli_test, `data`, `out`, `cube`, `tetra` and `flags_cube_tetra`.

# The tetrahedron at known gaps from the cube (see the file): 0.25, 1.5, touching,
# overlapping, 0.0625. Every value is a power of two, so the distances are exact.
set(gaps ${data}/poses_cube_tetra_gaps.txt)
set(distances_gaps "0.25\n1.5\n0\n0\n0.0625\n")
# poses_cube_tetra.txt: 0 exactly where the verdict is 1; 0.6 - 0.5 and 1.6 - 0.5
# as rounded in double; the far pose is 4.5 * sqrt(3) from the cube's corner.
set(distances_cube_tetra
    "0\n7.794228634059948\n0\n0.099999999999999978\n0\n0\n1.1000000000000001\n0\n")
set(common_keys "\"triangles_a\":12&&\"triangles_b\":4&&\"build_ms\":&&\"query_ms_total\":&&\"model_bytes\":&&\"volume_tests\":&&\"triangle_tests\":")
# The tetrahedron's face x = 0 resting on the cube's face x = 0.5: one face patch,
# the square [0, 0.5]^2 of y and z (area 0.25, centroid (0.5, 0.25, 0.25)), normal +x.
set(num_quarter "0.2[45][0-9]*")
set(face_patch_line
    "{\"pose\":2,\"colliding\":true,\"patches\":\\[{\"kind\":\"face\",\"point\":\\[0.5,${num_quarter},${num_quarter}\\],\"normal\":\\[1,0,0\\],\"area\":${num_quarter},\"length\":[0-9.e+-]+,\"depth\":0,\"penetrating\":false,\"pairs\":[1-9][0-9]*}\\]}\n")
# Overlapping: one penetrating patch where the surfaces cross (a curve).
set(overlap_patch_line
    "{\"pose\":3,\"colliding\":true,\"patches\":\\[{\"kind\":\"curve\",[^\n]*\"penetrating\":true,\"pairs\":[1-9][0-9]*}\\]}\n")
set(contact_lines_gaps
    "^{\"pose\":0,\"colliding\":false,\"patches\":\\[\\]}\n{\"pose\":1,\"colliding\":false,\"patches\":\\[\\]}\n${face_patch_line}${overlap_patch_line}{\"pose\":4,\"colliding\":false,\"patches\":\\[\\]}\n")

dovetail_cli_test(query_help_modes EXIT 0 ARGS query --help
                  STDOUT "--distance&&--tolerance EPS&&--contacts&&--contact-tolerance T&&rss")

# ---- --distance
dovetail_cli_test(query_distance_stdout EXIT 0 ARGS query ${cube} ${tetra} --poses ${gaps} --distance
                  STDOUT "^${distances_gaps}{[^\n]*}\n$&&\"method\":\"rss\"&&\"mode\":\"distance\"&&\"queries\":5&&\"colliding\":2&&\"distance_min\":0,&&\"distance_max\":1.5,&&${common_keys}")
dovetail_cli_test(query_distance_brute EXIT 0
                  ARGS query ${cube} ${tetra} --poses ${gaps} --distance --method brute --threads 2
                       --out ${out}/distances_brute.txt
                  STDOUT "^{[^\n]*}\n$&&\"method\":\"brute\"&&\"colliding\":2&&\"model_bytes\":0,&&\"threads\":2"
                  FILE ${out}/distances_brute.txt CONTENT "${distances_gaps}"
                  REMOVE ${out}/distances_brute.txt)
dovetail_cli_test(query_distance_rss_named EXIT 0
                  ARGS query ${cube} ${tetra} --poses ${gaps} --distance --method rss
                       --out ${out}/distances_rss.txt
                  STDOUT "\"method\":\"rss\""
                  FILE ${out}/distances_rss.txt CONTENT "${distances_gaps}"
                  REMOVE ${out}/distances_rss.txt)
dovetail_cli_test(query_distance_cube_tetra EXIT 0
                  ARGS query ${cube} ${tetra} --poses ${data}/poses_cube_tetra.txt --distance
                       --threads 2 --out ${out}/distances_cube_tetra.txt
                  STDOUT "\"queries\":8&&\"colliding\":5&&\"distance_max\":7.794228634059948,"
                  FILE ${out}/distances_cube_tetra.txt CONTENT "${distances_cube_tetra}"
                  REMOVE ${out}/distances_cube_tetra.txt)
dovetail_cli_test(query_distance_no_poses EXIT 0
                  ARGS query ${cube} ${tetra} --poses ${data}/poses_comments_only.txt --distance
                  STDOUT "^{[^\n]*}\n$&&\"queries\":0&&\"distance_min\":null&&\"distance_max\":null")

# ---- --tolerance: 1 when the distance is at most EPS (ties included)
dovetail_cli_test(query_tolerance_stdout EXIT 0
                  ARGS query ${cube} ${tetra} --poses ${gaps} --tolerance 0.25
                  STDOUT "^1\n0\n1\n1\n1\n{[^\n]*}\n$&&\"method\":\"rss\"&&\"mode\":\"tolerance\"&&\"tolerance\":0.25,&&\"within\":4,&&\"queries\":5&&${common_keys}"
                  REJECT_STDOUT "\"colliding\"")
dovetail_cli_test(query_tolerance_brute EXIT 0
                  ARGS query ${cube} ${tetra} --poses ${gaps} --tolerance 0.1 --method brute
                       --out ${out}/within_brute.txt
                  STDOUT "\"method\":\"brute\"&&\"tolerance\":0.1,&&\"within\":3,"
                  FILE ${out}/within_brute.txt CONTENT "0\n0\n1\n1\n1\n"
                  REMOVE ${out}/within_brute.txt)
# EPS = 0 is the collision verdict.
dovetail_cli_test(query_tolerance_zero EXIT 0
                  ARGS query ${cube} ${tetra} --poses ${data}/poses_cube_tetra.txt --tolerance 0
                       --threads 2 --out ${out}/within_zero.txt
                  STDOUT "\"within\":5,"
                  FILE ${out}/within_zero.txt CONTENT "${flags_cube_tetra}"
                  REMOVE ${out}/within_zero.txt)

# ---- --contacts
dovetail_cli_test(query_contacts_stdout EXIT 0 ARGS query ${cube} ${tetra} --poses ${gaps} --contacts
                  STDOUT "${contact_lines_gaps}{[^\n]*}\n$&&\"method\":\"boxtree\"&&\"mode\":\"contacts\"&&\"queries\":5&&\"colliding\":2,&&\"pairs_total\":[1-9]&&\"contact_tolerance\":1e-06,&&\"patches_total\":2,&&\"patches_face\":1,&&\"patches_curve\":1,&&\"patches_point\":0,&&\"patches_penetrating\":1&&${common_keys}")
# Every method finds the same pairs, so the same patches.
foreach(method boxtree dop6 dop14 dop18 dop26 aabb obb brute)
  dovetail_cli_test(query_contacts_${method} EXIT 0
                    ARGS query ${cube} ${tetra} --poses ${gaps} --contacts --method ${method}
                         --threads 2 --out ${out}/contacts_${method}.txt
                    STDOUT "^{[^\n]*}\n$&&\"method\":\"${method}\"&&\"patches_face\":1,&&\"patches_curve\":1,"
                    FILE ${out}/contacts_${method}.txt MATCHES "${contact_lines_gaps}$"
                    REMOVE ${out}/contacts_${method}.txt)
endforeach()
# A touching tolerance above the overlap's depth (0.5) makes it touching.
dovetail_cli_test(query_contacts_tolerance EXIT 0
                  ARGS query ${cube} ${tetra} --poses ${gaps} --contacts --contact-tolerance 0.75
                  STDOUT "\"contact_tolerance\":0.75,&&\"patches_penetrating\":0&&\"pose\":3,[^\n]*\"depth\":0.5,\"penetrating\":false")
# --all-pairs is what --contacts does anyway: accepted.
dovetail_cli_test(query_contacts_all_pairs EXIT 0
                  ARGS query ${cube} ${tetra} --poses ${gaps} --contacts --all-pairs
                  STDOUT "\"patches_total\":2,")

# ---- a bad pose line: the poses before it answered and written, exit 1
dovetail_cli_test(query_distance_bad_pose_line EXIT 1
                  ARGS query ${cube} ${tetra} --poses ${data}/poses_bad_line.txt --distance
                       --out ${out}/distances_bad_line.txt
                  STDERR "^dovetail: [^\n]*poses_bad_line.txt:5: expected 7 columns"
                  STDOUT "^{[^\n]*}\n$&&\"queries\":3&&\"colliding\":2&&\"error\":\"[^\"]*poses_bad_line.txt:5: "
                  FILE ${out}/distances_bad_line.txt CONTENT "0\n7.794228634059948\n0\n"
                  REMOVE ${out}/distances_bad_line.txt)
dovetail_cli_test(query_tolerance_bad_pose_line EXIT 1
                  ARGS query ${cube} ${tetra} --poses ${data}/poses_bad_line.txt --tolerance 0
                  STDERR "^dovetail: [^\n]*poses_bad_line.txt:5: expected 7 columns"
                  STDOUT "^1\n0\n1\n{[^\n]*}\n$&&\"queries\":3&&\"within\":2&&\"error\":")
dovetail_cli_test(query_contacts_bad_pose_line EXIT 1
                  ARGS query ${cube} ${tetra} --poses ${data}/poses_bad_line.txt --contacts
                       --out ${out}/contacts_bad_line.txt
                  STDERR "^dovetail: [^\n]*poses_bad_line.txt:5: expected 7 columns"
                  STDOUT "\"queries\":3&&\"patches_total\":2&&\"error\":"
                  FILE ${out}/contacts_bad_line.txt
                  MATCHES "^{\"pose\":0,\"colliding\":true,[^\n]*\n{\"pose\":1,\"colliding\":false,\"patches\":\\[\\]}\n{\"pose\":2,\"colliding\":true,\"patches\":\\[{\"kind\":\"face\",[^\n]*\\]}\n$"
                  REMOVE ${out}/contacts_bad_line.txt)

# ---- usage errors (exit 2)
set(q query ${cube} ${tetra} --poses ${gaps})
dovetail_cli_test(query_distance_and_contacts EXIT 2 ARGS ${q} --distance --contacts
                  STDERR "^dovetail: query: --distance and --contacts cannot be combined")
dovetail_cli_test(query_distance_and_tolerance EXIT 2 ARGS ${q} --tolerance 0.1 --distance
                  STDERR "--distance and --tolerance cannot be combined")
dovetail_cli_test(query_tolerance_and_contacts EXIT 2 ARGS ${q} --contacts --tolerance 0.1
                  STDERR "--tolerance and --contacts cannot be combined")
dovetail_cli_test(query_distance_all_pairs EXIT 2 ARGS ${q} --distance --all-pairs
                  STDERR "--all-pairs cannot be combined with --distance")
dovetail_cli_test(query_tolerance_all_pairs EXIT 2 ARGS ${q} --all-pairs --tolerance 1
                  STDERR "--all-pairs cannot be combined with --tolerance")
dovetail_cli_test(query_contact_tolerance_alone EXIT 2 ARGS ${q} --contact-tolerance 0.1
                  STDERR "--contact-tolerance needs --contacts")
dovetail_cli_test(query_contact_tolerance_distance EXIT 2
                  ARGS ${q} --distance --contact-tolerance 0.1
                  STDERR "--contact-tolerance needs --contacts")
foreach(bad -1 nan inf 1e999 abc)
  dovetail_cli_test(query_tolerance_bad_${bad} EXIT 2 ARGS ${q} --tolerance=${bad}
                    STDERR "--tolerance must be a finite number >= 0, not '${bad}'")
endforeach()
dovetail_cli_test(query_tolerance_missing_value EXIT 2 ARGS ${q} --tolerance
                  STDERR "option '--tolerance' needs a value")
dovetail_cli_test(query_contact_tolerance_negative EXIT 2
                  ARGS ${q} --contacts --contact-tolerance=-1e-6
                  STDERR "--contact-tolerance must be a finite number >= 0")
dovetail_cli_test(query_distance_collision_method EXIT 2 ARGS ${q} --distance --method dop14
                  STDERR "method 'dop14' has no distance query; --distance uses rss")
dovetail_cli_test(query_tolerance_unknown_method EXIT 2 ARGS ${q} --tolerance 1 --method octree
                  STDERR "unknown method 'octree' for --tolerance; valid methods: rss, brute")
dovetail_cli_test(query_rss_without_distance EXIT 2 ARGS ${q} --method rss
                  STDERR "method 'rss' [^\n]*--distance and --tolerance only")
dovetail_cli_test(query_contacts_rss EXIT 2 ARGS ${q} --contacts --method rss
                  STDERR "method 'rss' [^\n]*--distance and --tolerance only")
