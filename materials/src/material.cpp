// Material models: implemented by the materials work (see material.hpp).
