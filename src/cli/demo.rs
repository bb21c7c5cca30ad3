use clap::Args;
#[derive(Args, Debug)]
pub struct DemoArgs {}
pub fn run(_a: DemoArgs) -> crate::error::Result<()> {
    Ok(())
}
