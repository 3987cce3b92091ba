"""Standard manoeuvres run on models and ships, and the IMO indices read from any log."""
