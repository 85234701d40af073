//! Safe wrapper over SUNDIALS (the only module with `unsafe`). (Being written.)
