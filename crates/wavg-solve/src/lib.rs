//! Forward and inverse weighted-average problems (paper Sections 3.3-3.4).
