//! `flourish style check`: placeholder replaced below.
