#pragma once
// Velocity smoothing for tensile stability (Eq. 66-73, spec section 9): each centre moves its
// velocity towards the weighted average of its neighbours', every neighbour takes an opposite
// share so that momentum is conserved, and the kinetic energy each node loses or gains goes into
// its internal energy. Every change is computed from the velocities before smoothing and then
// applied, so the result does not depend on node order or thread count. Ghosts take no part.
//
// Prescribed velocities (prescribed.hpp): a held component is not changed. Its node still takes
// part (its velocity enters its neighbours' averages, and as a centre it shares its change with
// them), but the change it would receive is dropped: that momentum comes from the region (the
// caller books it from SmoothingScratch::total_change), and since every node's heat is its own
// kinetic-energy change (Eq. 73) the energy booking closes without a work term.

#include <cstddef>
#include <cstdint>
#include <vector>

#include "gpa/engine/colouring.hpp"
#include "gpa/engine/compressed_rows.hpp"
#include "gpa/engine/fields.hpp"
#include "gpa/engine/weights.hpp"

namespace gpa {

struct SmoothingOptions {
    double coefficient = 0.1;   // C_cs (Eq. 67)
    bool tension_only = false;  // only centres with negative pressure
    // Per node, bit c set: component c is prescribed and is left as it is (nullptr: none).
    const std::uint8_t* held = nullptr;
};

// Scratch kept between steps.
struct SmoothingScratch {
    std::vector<double> centre_change;  // dv_i per component, dim * n
    std::vector<double> share;          // M_i / sum_k R_ik M_k per centre
    std::vector<double> total_change;   // dV_i per component, dim * n (held components: the change dropped)
};

// Smooths the velocities of nodes [0, real_count) over the lists' real pairs; `plan` must be a
// conflict-free plan of the same lists. Adds the converted kinetic energy to the specific
// internal energy. Returns the kinetic energy moved into internal energy (J).
template <class G>
double smooth_velocities(const CompressedRows& lists, const ScatterPlan& plan, WeightKind weight,
                         const PairFields<G::dim>& pairs, std::size_t real_count, const SmoothingOptions& options,
                         std::array<double*, G::dim> velocity, const double* mass, const double* pressure,
                         double* internal_energy, SmoothingScratch& scratch);

}  // namespace gpa
