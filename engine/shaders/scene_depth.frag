#version 460
// Depth only: no colour output (the pipeline has no colour attachments).
void main() {}
