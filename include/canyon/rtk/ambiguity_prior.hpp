#pragma once
// A new ambiguity started from the filter's position (beyond the paper; the issue's "keep fixed ambiguities through
// blockages" and "initialise a re-acquired ambiguity from a held fixed position").
//
// Without it, a signal that slipped or came back after an outage starts from its code, N_sd = (phase - code) /
// lambda with a sigma of initial_ambiguity_sigma_cyc (30 cycles), and must be learnt again from the code, which in a
// street canyon takes minutes of biased pseudoranges. With the position held (fixed ambiguities, then the VIO
// increments through a blockage), its DD phase against a held ambiguity r of the same DD group determines it:
//   Phi_sr = h . (p - p0) + lambda_s N_s - lambda_r N_r - (k_s I_s - k_r I_r) + e        (dd_update.cpp's phase row)
//   N_s    = (Phi_sr + h . p0 + lambda_r N_r + k_s I_s - k_r I_r - h . p) / lambda_s - e / lambda_s,
// a linear combination of held states (position, N_r, the ionosphere states) plus the phase noise, added with its
// covariances (FilterState::add_combination): what the filter learns later moves it as well, and the ambiguity
// resolution fixes it once its success rate allows (the prior is in its covariance). A slip is thereby repaired (the
// state restarts at the old value plus the integer jump) and a re-acquired signal starts converged.
//
// It is used only while the start's DD sigma (of N_s - (lambda_r / lambda_s) N_r: the terms above without N_r's, whose
// variance is the receiver's phase bias common to the group, never observed; in cycles) is at most max_sigma_cyc
// (lambda/6.6, 0.15 cycles: the integer is then right with a probability of 99.9 %) and, between two signals of one
// wavelength (an integer DD ambiguity), while the start lies within two of its sigmas of an integer (a reflected phase
// or a position that is off lands anywhere in the cycle); otherwise the code start stays.
// The reference r is the same group's held ambiguity with phase at this epoch and the smallest variance. The epoch's
// phase enters both the start and the update that follows: its noise (millimetres) is counted twice, small beside
// the position's (centimetres) that the sigma test bounds.

#include <vector>

#include "canyon/rtk/filter_state.hpp"
#include "canyon/rtk/single_difference.hpp"

namespace canyon::rtk {

/// One ambiguity started from the position: its DD start against the reference (for the report of repairs against
/// a simulator's true integers, tests/bench/repair_truth.cpp).
struct AmbiguityStart {
  StateKey key;
  StateKey reference;
  double dd_cyc = 0.0;        ///< N_s - (lambda_r / lambda_s) N_r as started (cycles)
  double dd_sigma_cyc = 0.0;  ///< its sigma
  double wavelength_m = 0.0;  ///< lambda_s
  bool integer = false;       ///< lambda_r == lambda_s: the DD ambiguity is an integer
};

/// Restarts each ambiguity of `added` (keys new to the filter this epoch, started from their code) from the
/// position as above where the start's sigma is at most `max_sigma_cyc`; `sds` are the epoch's single differences
/// (state indices need not be assigned). Returns the ambiguities started from the position.
std::vector<AmbiguityStart> start_ambiguities_from_position(FilterState& state, const std::vector<SingleDiff>& sds,
                                                            const std::vector<StateKey>& added, double max_sigma_cyc);

}  // namespace canyon::rtk
