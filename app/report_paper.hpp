/*
 * The paper report: reads a study folder (one results folder per scene of resources/scenes/paper/) and
 * writes <outDir>/README.md and <outDir>/fig-*.png, the analogues of Figures 1–10 of the paper
 * "Exploring the effects of stress history on the drained and undrained cyclic behaviour of granular
 * materials", with a table of the paper's numbers beside ours (each citing its section/figure).
 * Runs that are missing are listed as "not run" and their figures skipped; garbled files throw
 * InputError/IoError naming the file and line/column. Optional runs *-md (Mindlin–Deresiewicz contact law,
 * issue 9) add a section comparing both contact laws. Figures from a previous report that were not
 * written this time (a run went missing) are removed, so the folder never shows stale images.
 * Needs a QApplication (fl::charts::ensureApplication()).
 */
#pragma once

#include <string>
#include <vector>

namespace fl::report {

struct ReportSummary {
  std::string readme;                  // path of the README.md written
  std::vector<std::string> figures;    // file names of the figures written
  std::vector<std::string> notRun;     // folders of the study that were not run
  std::vector<std::string> incomplete; // folders with a partial run
};

// notesFile: a Markdown file included verbatim as the discussion section ("" = none). A notes file that
// is named but does not exist is an IoError.
ReportSummary writePaperReport(const std::string& studyDir, const std::string& outDir, const std::string& notesFile);

// The folders the report reads, in order (the optional *-md runs last).
const std::vector<std::string>& studyFolders();
const std::vector<std::string>& optionalStudyFolders();

}  // namespace fl::report
