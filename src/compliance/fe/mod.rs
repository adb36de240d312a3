//! 3D finite elements (20-node serendipity hexahedra) for the global tooth deformation.
