#pragma once
/// \file report_diff.h
/// What changed between two reports of one scenario: the baseline that
/// `dovetail regress --baseline` compares against, and the run just made.
///
/// Why: expectations say what must hold; a regression suite must also catch
/// what changed without breaking one (a grasp a frame later, a part seated
/// 0.2 mm off, one more contact). Runs are deterministic, so the comparison
/// is exact: any difference in the report's numbers is a change. Paths to the
/// scenario are made alike first, so a checkout in another folder changes
/// nothing.

#include <cstddef>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

namespace dovetail::cli {

/// One difference: where in the report (`steps[insert].done_at`), and the
/// value now and in the baseline as JSON (`null` where there is none).
struct ReportChange {
  std::string where;
  std::string now;
  std::string was;

  /// `steps[insert].done_at: 2.5, was 2.411`.
  std::string str() const;
};

/// Every difference between `baseline` and `now`, in the order of the
/// report's fields, at most `limit` of them; `total` gets how many there are
/// in all, the outcome and the error first. The reports' `file` fields are
/// not compared; the scenario's path in every text is read as its file name
/// without the line number after it (`peg.lua:32` as `peg.lua`: a comment
/// added above a rule is no change), and the paths of its folder as
/// relative to it.
///
/// With a `tolerance` above 0, two numbers a and b are alike when |a - b| <=
/// tolerance * max(1, |a|, |b|), so are two texts with the same words and
/// alike numbers between them, and the state hash, which changes with any
/// bit of a pose, is not compared.
std::vector<ReportChange> report_changes(const nlohmann::ordered_json& baseline,
                                         const nlohmann::ordered_json& now, std::size_t limit,
                                         std::size_t& total, double tolerance = 0);

/// Reads a report's text with its fields in the file's order. Throws
/// std::runtime_error for text that is no JSON (saying where, as the parser
/// does: "at line 3, column 1: ...") or that nests deeper than 32 levels
/// (a report nests 4: deeper text is no report, and would only exhaust the
/// stack of whatever walks it).
nlohmann::ordered_json parse_report(const std::string& text);

/// Whether `report` is a Dovetail scenario report (its `format`).
bool is_scenario_report(const nlohmann::ordered_json& report);

}  // namespace dovetail::cli
