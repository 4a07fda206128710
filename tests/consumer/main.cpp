// Embeds gpa: fills a plane-strain block, computes the paper's geometry factor, prints it; writes
// the block as a snapshot, reads it back and draws it as a PNG (the io library and its libpng).
#include <cstdio>
#include <filesystem>

#include "gpa/engine/drivers.hpp"
#include "gpa/engine/lattice.hpp"
#include "gpa/engine/neighbours.hpp"
#include "gpa/io/output.hpp"
#include "gpa/io/render.hpp"

int main() {
    gpa::NodeStore nodes(gpa::GeometryKind::PlaneStrain);
    gpa::LatticeBlock block;
    block.last = {7, 7, 1};
    gpa::fill_lattice(nodes, block);
    const auto lists = gpa::find_neighbours(nodes, 1.0, nodes.size());
    gpa::compute_velocity_gradient<gpa::PlaneStrain>(lists, gpa::WeightKind::Gpa, gpa::gradient_fields<2>(nodes, 1.0));
    const std::size_t centre = 3 * 7 + 3;
    std::printf("alpha_z=%.4f\n", nodes.alpha[1][centre]);
    const bool alpha_ok = nodes.alpha[1][centre] > 0.6305 && nodes.alpha[1][centre] < 0.6307;

    const auto folder = std::filesystem::temp_directory_path() / "gpa_consumer_snapshot";
    std::filesystem::remove_all(folder);
    std::filesystem::create_directories(folder);
    gpa::io::SnapshotSeries(folder).write(nodes, nodes.size(), 0.0);
    const auto series = gpa::io::read_pvd(gpa::io::find_pvd(folder));
    gpa::io::RenderOptions options;
    options.field = "alpha";
    const auto picture = gpa::io::render_snapshot(gpa::io::load_snapshot(series, 0), gpa::GeometryKind::PlaneStrain, options);
    const std::string png = gpa::io::encode_png(picture.image);
    std::printf("picture %dx%d, %zu nodes, %zu PNG bytes\n", picture.image.width, picture.image.height, picture.discs, png.size());
    const bool picture_ok = picture.discs == nodes.size() && png.compare(1, 3, "PNG") == 0;
    return alpha_ok && picture_ok ? 0 : 1;
}
