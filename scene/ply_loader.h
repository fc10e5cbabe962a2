// scene/ply_loader.h: Stanford PLY meshes (the format of scanned models such as the Stanford
// bunny): ASCII, binary little- and big-endian; vertex x, y, z (with nx, ny, nz when a file has
// all three) and faces as index lists, fanned into triangles. Other elements and properties
// (colours, confidence, edges) are read past and dropped.
#pragma once

#include <stdexcept>
#include <string>

#include "scene/scene.h"

namespace shadowlab::scene {

// What is wrong with a PLY file, without the file's name (the mesh loader adds it and the
// scene's JSON path).
class PlyError : public std::runtime_error {
public:
    using std::runtime_error::runtime_error;
};

// Appends the file's triangles to `mesh` (positions, and normals when the file has them).
// Throws PlyError on anything malformed: a bad header, counts the bytes cannot hold, an index
// out of range, a non-finite coordinate, a face of fewer than three corners, no faces.
void loadPly(const std::string& bytes, TriangleMesh& mesh);

}  // namespace shadowlab::scene
