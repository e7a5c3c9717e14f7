//! Linear coupling constraints C·p = c0 between wings and the Table 3.1 configurations (thesis §3.2.5).
