"""A reliable oracle [RAA09]: interval and revised affine arithmetic enclosures of the KRS
distance over ray segments and boxes, and the certified hole / false-hit counts they give."""
