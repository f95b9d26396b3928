// The texts femdyn study writes from its report (cli/study.cpp): study.csv, study.gp (gnuplot),
// study.md and the JSON object, and the sentences they share.
#pragma once
#include <nlohmann/json.hpp>
#include <string>

#include "validation/study.hpp"

namespace femdyn::cli {

std::string csv_text(const validation::StudyReport& rep, const std::string& command);
std::string gnuplot_text(const validation::StudyReport& rep);
std::string markdown_text(const validation::StudyReport& rep, const std::string& command);
nlohmann::ordered_json report_json(const validation::StudyReport& rep, const std::string& command,
                                   const validation::StudyOptions& o,
                                   const validation::StudyEstimate& e);
// "both engines interpolate at the 20 samples (…)"; "each run once as a warm-up (…)"; the
// formulation sentence of a closed or coupled model.
std::string sampling_short(const validation::StudyReport& rep);
std::string timing_text(const validation::StudyReport& rep);
std::string formulation_text(const validation::StudyReport& rep);

}  // namespace femdyn::cli
