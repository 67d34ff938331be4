// Candidates of the evaluation: what a shadow map could store, each judged by the error of its
// reconstruction against PCF (evaluate.h).
//
// A candidate is either
//  - a set of m candidate functions (functions.h): the shadow map stores b(z) = (f_1(z), ..,
//    f_m(z)) and the reconstruction is the sharp lower bound of 2015 Problem 1 on the depth grid,
//    computed by the linear program (grid_lp.h); or
//  - a named technique with a closed form in include/msm (PCF itself, VSM, ESM, EVSM2/4, Hamburger
//    and Hausdorff 4MSM, TMSM), evaluated by that closed form as the renderer would (float, its
//    biasing): the marks of the histogram next to the candidates.
//
// Candidate lists (the `--candidates` of `msm evaluate`), items separated by commas:
//   z+z2+z3+z4        the functions named (functions.h), in any order (the set is what counts)
//   power2 .. power6  aliases: z..z^m (m = 2, 3, 4, 6); trig2, trig3, trig4, trig6: the first m of
//                     sin 2piz, cos 2piz, sin 4piz, cos 4piz, sin 6piz, cos 6piz (2015 Eq. (1))
//   pcf, vsm, esm, evsm2, evsm4, hamburger4, hausdorff4, tmsm   the closed forms
//   named             all of the above aliases and closed forms
//   all:K             every set of K of the 37 functions (all:4 = the paper's C(37, 4) = 66045),
//                     in lexicographic order of the function indices
//   sample:K:N[:S]    N different sets of K functions drawn uniformly (seed S, default 1), in
//                     lexicographic order
// Duplicates (the same set reached twice, e.g. power4 inside all:4) are evaluated once; the first
// occurrence keeps its place and collects the aliases.
#pragma once

#include <cstdint>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

namespace msm::evaluate {

// Closed-form techniques (include/msm): what each computes is documented in evaluate.h.
enum class Technique { lp, pcf, vsm, esm, evsm2, evsm4, hamburger4, hausdorff4, tmsm };
std::string_view to_string(Technique technique);

inline constexpr int kMaxFunctions = 8; // m <= 8: at most 9 rows in the linear program

struct Candidate {
  std::string name; // "z+z2+z3+z4" (function names in index order), or the technique's name
  Technique technique = Technique::lp;
  std::vector<int> functions;       // lp: sorted indices into candidate_functions(); else empty
  std::vector<std::string> aliases; // e.g. {"power4"}
  bool listed = false;              // named in the list (explicitly or by an alias), not only drawn by all: / sample:
  int m() const { return technique == Technique::lp ? int(functions.size()) : 0; }
  bool has_alias(std::string_view alias) const;
};

// Bad candidate lists: unknown names, repeated functions, bad K/N. what() says which item.
struct CandidateError : std::invalid_argument {
  using std::invalid_argument::invalid_argument;
};

// Expands a candidate list (syntax above). Throws CandidateError.
std::vector<Candidate> parse_candidates(std::string_view spec);

// The number of K-subsets of n things (exact up to 2^63; n <= 64).
std::uint64_t binomial(int n, int k);
// The K-subset of {0, .., n-1} of lexicographic rank `rank` (0-based), ascending.
std::vector<int> unrank_combination(int n, int k, std::uint64_t rank);

} // namespace msm::evaluate
