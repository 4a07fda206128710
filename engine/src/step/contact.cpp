#include "step/contact.hpp"

#include "gpa/engine/separation.hpp"

namespace gpa {

void Contact::separate(CompressedRows& lists, const NodeStore& nodes, std::size_t real, double influence_distance) {
    if (!separation_) return;
    std::array<double*, 3> towards{};
    if (sliding_) {
        for (int c = 0; c < nodes.dim(); ++c) {
            resize_with_slack(direction_[c], nodes.size());
            towards[c] = direction_[c].data();
        }
    }
    remove_open_pairs(lists, nodes, real, failed_pairs_separate_, closing_speed_.data(), towards, influence_distance);
}

void Contact::mirror_directions(GhostSet& ghosts, int dim, std::size_t real) {
    if (!sliding_ || ghosts.empty()) return;
    ghosts.mirror_vector_field({direction_[0].data(), direction_[1].data(), dim == 3 ? direction_[2].data() : nullptr}, dim, real);
}

}  // namespace gpa
