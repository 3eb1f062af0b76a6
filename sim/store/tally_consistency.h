#pragma once
// The identities every exact tally satisfies, whatever photons, threads,
// ranks, checkpoints or merges made it (sim/store/tally.h, SPEC section 4), used
// to refuse a file whose sums were damaged or edited:
//  - the ledger balances exactly: for every channel,
//    sum over lobes of exited + absorbed + truncated + lost - roulette =
//    photons x 2^60 (roulette, signed: 0 with the analog estimator);
//  - each lobe's exited is the exact sum of its bins' S1 (Tally::exact_ledger);
//  - no bin counts more photons than were launched, nor, with the analog
//    estimator, do all bins together (a photon exits at most once; with
//    expected-value scoring it may exit in many bins, each counting it once);
//  - with the analog estimator, each exit weighs at most 1 (2^60 in fixed
//    point) and w^2 <= w, so a bin's S1 <= count x 2^60 and S2 <= S1 for
//    every channel (with expected-value scoring a photon's total in a bin
//    may exceed 1 by what Russian roulette created for it).
#include <string>

#include "sim/store/exact_tally.h"

namespace fiberlab::sim {

// "" when `t` satisfies every identity above; otherwise the first one that
// fails, in words naming the lobe, bin or channel (for an error line that
// names the file and direction).
// `one_exit_per_photon`: the analog estimator's tally (Settings::estimator).
std::string tally_inconsistency(const ExactTally& t, bool one_exit_per_photon);

}  // namespace fiberlab::sim
